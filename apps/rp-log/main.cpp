// rp-log: tools for the CSV logs of control programs (`-log FILE`).
//
//   rp-log recover FILE.part [OUT]
//
// recover: a run killed (SIGKILL, power loss) leaves its rows in FILE.part, the last one possibly
// cut. Writes OUT (default: FILE, FILE.part without `.part`; `-` for stdout) with the log's
// complete header and every complete row; the cut row is left out. OUT must not exist.
// Exit status: 0 done, 2 bad usage or input (one line on stderr naming the file and line).
#include <exception>
#include <iostream>
#include <string>

#include "rp/rt/LogRecovery.hpp"

namespace {

const char* const kUsage =
    "usage: rp-log recover FILE.part [OUT]\n"
    "  recover  writes the complete rows of a log a killed run left in FILE.part to OUT\n"
    "           (default FILE; '-' for stdout): the full header, then every complete row\n";

int usage(const std::string& error) {
  std::cerr << "rp-log: " << error << "\n" << kUsage;
  return 2;
}

}  // namespace

int main(int argc, char* argv[]) {
  if (argc == 2 && (std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h")) {
    std::cout << kUsage;
    return 0;
  }
  if (argc < 2) return usage("no command");
  const std::string command = argv[1];
  if (command != "recover") return usage("unknown command '" + command + "'");
  if (argc < 3 || argc > 4) return usage("recover takes FILE.part and, optionally, OUT");
  const std::string part = argv[2];
  std::string out;
  if (argc == 4) {
    out = argv[3];
  } else if (part.size() > 5 && part.compare(part.size() - 5, 5, ".part") == 0) {
    out = part.substr(0, part.size() - 5);
  } else {
    return usage(part + ": not named FILE.part: name the output (rp-log recover " + part + " OUT)");
  }
  try {
    const rp::LogRecovery r = rp::recoverLog(part, out);
    std::cerr << "rp-log: " << part << ": " << r.rows << " complete rows of " << r.columns << " columns written to "
              << (out == "-" ? std::string("stdout") : out)
              << (r.cutRowDropped ? " (the cut last row left out)" : "") << "\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "rp-log: " << e.what() << "\n";
    return 2;
  }
}
