// libFuzzer target for URDF loading (loadUrdf): any input either loads as a model or throws
// UrdfError naming the file; nothing else may happen (no hang, no crash, no other exception, no
// sanitizer report). loadUrdf reads files, so each input is written to a scratch file first.
#include <console_bridge/console.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "rp/model/Kinematics.hpp"
#include "rp/model/UrdfModel.hpp"

namespace {

std::string scratchFile() {
  const std::string file = "/tmp/rp_urdf_fuzzer_" + std::to_string(::getpid()) + ".urdf";
  console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_NONE);  // urdfdom's own messages
  return file;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string file = scratchFile();
  std::FILE* f = std::fopen(file.c_str(), "wb");
  if (!f) std::abort();
  if (size > 0 && std::fwrite(data, 1, size, f) != size) std::abort();
  std::fclose(f);
  // The first byte chooses the options, so that named tips and dynamics are explored too.
  rp::UrdfOptions options;
  options.requireDynamics = size > 0 && (data[0] & 1);
  if (size > 0 && (data[0] & 2)) options.tip = "tool";
  try {
    const std::unique_ptr<rp::ManipulatorModel> model = rp::loadUrdf(file, options);
    const int n = model->getNumberOfJoints();
    if (n < 1) std::abort();
    rp::ManipulatorData scratch(*model);
    const rp::Transform& T = rp::forwardKinematics(*model, scratch, rp::JointVector(n));
    if (!T.allFinite()) std::abort();  // a loaded model is usable
  } catch (const rp::UrdfError& e) {
    // The message names the file: "FILE: ..." or, for malformed XML, "FILE:LINE:COLUMN: ...".
    const std::string what = e.what();
    if (what.rfind(file + ":", 0) != 0) std::abort();
    const char next = what.size() > file.size() + 1 ? what[file.size() + 1] : '\0';
    if (next != ' ' && !(next >= '0' && next <= '9')) std::abort();
  }
  return 0;
}
