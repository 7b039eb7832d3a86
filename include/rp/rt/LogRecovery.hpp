#pragma once
/// @file
/// recoverLog(): turns the file a LogWriter was writing (`FILE.part` of a run that was killed, or
/// a log streamed to a FIFO) into a complete CSV log.

#include <cstddef>
#include <cstdint>
#include <string>

namespace rp {

/// What recoverLog() found and wrote.
struct LogRecovery {
  std::uint64_t rows = 0;      ///< complete rows written
  std::size_t columns = 0;     ///< columns of the log, `t` included
  bool cutRowDropped = false;  ///< whether the input ended in a cut row (left out)
};

/// Writes the complete log held in a log being written: the widest header, then every complete
/// row padded to its width; a last row cut short (no end of line, as a killed run leaves it) is
/// left out. The input is what LogWriter writes while running: a header line `t,...`, rows, and a
/// wider header line before the rows of a program that started logging later.
/// @param[in] partFile  the log being written, e.g. `run.csv.part`
/// @param[in] outFile   the complete log to create (it must not exist), or `-` for stdout
/// @return the rows and columns written
/// @throws std::runtime_error naming the file (and line) if the input is not such a log, is empty,
///         or the output cannot be created or written (a partly written output is removed)
/// Real-time safe: no.
LogRecovery recoverLog(const std::string& partFile, const std::string& outFile);

}  // namespace rp
