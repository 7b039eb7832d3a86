#pragma once
// Opening a page of the Scene Viewer in the user's default browser (-qmotor).

#include <string>

namespace rp::internal {

/// Opens `url` in the user's default browser with `xdg-open` when a display is present
/// (`DISPLAY` or `WAYLAND_DISPLAY` set and not empty); the browser's output goes to /dev/null and
/// the program does not wait for it. Says on stderr what it did: "opening it in the default
/// browser", or why not (no display, no xdg-open), so the printed URL is always the way in.
/// @param[in] url  the page's URL (with its token, if the viewer has one)
/// @param[in] what the page's name in the messages (e.g. "QMotor")
void openInBrowser(const std::string& url, const std::string& what);

}  // namespace rp::internal
