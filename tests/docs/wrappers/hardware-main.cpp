// Wrapper of docs/hardware.md's fragments that continue an earlier one: its header, in main().
#include "rp/io/HwServerIoBoard.hpp"

int main() {
@FRAGMENT@
  return 0;
}
