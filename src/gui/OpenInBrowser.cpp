// Opening a page in the user's default browser with xdg-open (src/gui/OpenInBrowser.hpp).
#include "OpenInBrowser.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <thread>

extern char** environ;

namespace rp::internal {

namespace {
bool hasDisplay() {
  for (const char* name : {"DISPLAY", "WAYLAND_DISPLAY"}) {
    const char* value = std::getenv(name);
    if (value != nullptr && *value != '\0') return true;
  }
  return false;
}
}  // namespace

void openInBrowser(const std::string& url, const std::string& what) {
  if (!hasDisplay()) {
    std::cerr << "rp: " << what << ": no display (DISPLAY is not set): open the URL above in a browser" << std::endl;
    return;
  }
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  // The browser's chatter stays out of the program's output; it reads nothing from the terminal.
  for (int fd : {STDIN_FILENO, STDOUT_FILENO, STDERR_FILENO})
    posix_spawn_file_actions_addopen(&actions, fd, "/dev/null", fd == STDIN_FILENO ? O_RDONLY : O_WRONLY, 0);
  std::string program = "xdg-open", argument = url;
  char* argv[] = {program.data(), argument.data(), nullptr};
  pid_t pid = -1;
  const int error = posix_spawnp(&pid, "xdg-open", &actions, nullptr, argv, environ);
  posix_spawn_file_actions_destroy(&actions);
  if (error != 0) {
    std::cerr << "rp: " << what << ": cannot start xdg-open (" << std::strerror(error)
              << "): open the URL above in a browser" << std::endl;
    return;
  }
  std::cerr << "rp: " << what << ": opening it in the default browser (xdg-open)" << std::endl;
  // xdg-open returns once the browser has been handed the page; reap it without waiting here.
  std::thread([pid] {
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
  }).detach();
}

}  // namespace rp::internal
