#pragma once
// Whether a program that drove an arm by torque across processes ended in the safe stop a
// machine's stalls bring about, rather than in a fault of the code under test.
#include <string>

namespace rp::test {

// True if `output` (a program's stdout and stderr) reports that its servo loop missed cycles and
// that the arm then stopped at a joint velocity limit, with the shutdown's exit status 3. On a
// machine that stalls the process for milliseconds (a shared VM), the loop that drives the arm
// from another process misses cycles, the arm overshoots the task's speed and the limit stops
// it: the safe reaction, which says nothing about whether the task runs on a machine that keeps
// the servo loop's deadlines. The tests that drive an arm by torque across processes skip, with
// the program's own report, when this is how their program ended.
inline bool stoppedByAStalledServoLoop(const std::string& output) {
  return output.find("servo cycles missed") != std::string::npos &&
         output.find("velocity") != std::string::npos && output.find("exceeds the limit") != std::string::npos &&
         output.find("exit status 3") != std::string::npos;
}

}  // namespace rp::test
