// Wrapper of docs/hardware.md's fragments: their own #include lines first, then <iostream>, the
// fragment in main() (the fragments talk to devices, so they are compiled, not run).
#include <iostream>

int main() {
@FRAGMENT@
  return 0;
}
