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

// How long a command waits for the device to confirm its outputs (a hardware server's cycle) [ms].
constexpr int kConfirmTimeoutMs = 2000;

// Sets two outputs and waits until the device confirmed them (IoBoard::confirmWrites); on failure
// stores the board's message in `error`.
bool driveTwoLines(IoBoard& board, int lineA, bool valueA, int lineB, bool valueB, std::string& error);

}  // namespace rp::internal
