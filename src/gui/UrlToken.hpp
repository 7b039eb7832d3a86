// The characters a Scene Viewer token may have (internal: RoboticPlatform::setGuiToken() and
// SceneViewer::start() check tokens with it).
#pragma once

#include <string>

namespace rp::internal {

// Whether `token` can be a Scene Viewer token: pages present it in the URL as it is (the viewer
// does not percent-decode), so at most 256 of the URL's unreserved characters ('a&b c' locked
// every page out).
inline bool isUrlToken(const std::string& token) {
  return token.size() <= 256 &&
         token.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789-._~") == std::string::npos;
}

}  // namespace rp::internal
