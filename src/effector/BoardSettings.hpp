#pragma once
// rp.cfg settings of objects worked by two digital outputs (DefaultGripper, DefaultToolChanger):
// which board (simulated, modbus, hwserver), how to reach it, and the two lines.
#include <memory>
#include <string>

#include "rp/core/Configuration.hpp"
#include "rp/io/IoBoard.hpp"

namespace rp::internal {

void declareTwoLineBoardSettings(SettingSchema& schema, const char* lineA, const char* lineB);

struct TwoLineBoard {
  std::unique_ptr<IoBoard> board;  // null without a `board` setting
  int lineA = 0;                   // board line numbers to drive
  int lineB = 1;
  std::string deviceError;         // the board could not be reached (not a configuration error)
};

// Throws ConfigError (FILE:LINE) for invalid or missing settings.
TwoLineBoard createTwoLineBoard(const ConfigSection& section, const char* lineA, const char* lineB);

// Sets two outputs; on failure stores "NAME: what failed: board message" in `error`.
bool driveTwoLines(IoBoard& board, int lineA, bool valueA, int lineB, bool valueB, std::string& error);

}  // namespace rp::internal
