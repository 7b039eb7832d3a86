#pragma once
// JSON string escaping for the `read` replies of the end-effector classes.
#include <string>

namespace rp::internal {

inline std::string jsonString(const std::string& text) {
  std::string out;
  out.reserve(text.size() + 2);
  out.push_back('"');
  for (char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    if (static_cast<unsigned char>(c) < 0x20) continue;  // control characters are dropped
    out += c;
  }
  out.push_back('"');
  return out;
}

}  // namespace rp::internal
