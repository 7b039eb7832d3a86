// libFuzzer target for the control-program (qmotorConfig) file reader: any input either parses
// or throws ConfigError with a FILE:LINE message quoting at most a short excerpt; nothing else may
// happen (no crash, no other exception, no sanitizer report). Parsed values of the settings a
// control program takes must pass the same whole-number checks ControlProgram applies.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "rp/core/Configuration.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const rp::ParameterFile file = rp::ParameterFile::parse(text, "fuzz.cfg");
    if (file.fileName() != "fuzz.cfg") std::abort();
    int previous = 0;
    for (const auto& e : file.entries()) {
      // Lines in file order, each a name with at least one value.
      if (e.line <= previous || e.name.empty() || e.values.empty()) std::abort();
      previous = e.line;
      const rp::ConfigError located = file.errorAt(e, "x");
      if (located.line() != e.line || located.file() != "fuzz.cfg") std::abort();
    }
  } catch (const rp::ConfigError& e) {
    // The message names the file and the line, and quotes no more than an excerpt of the input
    // (an error about the whole file is impossible for text that was never read from disk).
    if (std::string(e.what()).rfind("fuzz.cfg:", 0) != 0 || e.line() < 1) std::abort();
    if (e.message().size() > 400) std::abort();
  }
  return 0;
}
