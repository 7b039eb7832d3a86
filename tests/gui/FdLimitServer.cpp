// A Scene Viewer in a process of its own whose file descriptors the test can use up: the test
// (SceneViewer_test.cpp, OutOfFileDescriptors) drives it through stdin and stdout.
//   gui_fd_limit_server LIMIT   lowers RLIMIT_NOFILE to LIMIT, starts the viewer on 127.0.0.1,
//                               prints "port N"; then, one command a line:
//   fill     opens /dev/null until the process is out of descriptors, prints "filled N"
//   release  closes them again, prints "released"
//   stats    prints "stats PAGES OPEN CLOSED_FOR_ROOM REFUSED ACCEPT_FAILURES"
// and ends at the end of its input.
#include <fcntl.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <string>
#include <vector>

#include "rp/gui/SceneViewer.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: gui_fd_limit_server LIMIT\n";
    return 2;
  }
  rlimit limit{};
  getrlimit(RLIMIT_NOFILE, &limit);
  limit.rlim_cur = static_cast<rlim_t>(std::atoi(argv[1]));
  if (setrlimit(RLIMIT_NOFILE, &limit) != 0) {
    std::perror("setrlimit");
    return 2;
  }
  rp::SceneViewer& viewer = rp::SceneViewer::instance();
  rp::SceneViewerOptions options;
  options.port = 0;
  viewer.start(options);
  std::cout << "port " << viewer.getPort() << std::endl;
  std::vector<int> held;
  for (std::string line; std::getline(std::cin, line);) {
    if (line == "fill") {
      for (int fd; (fd = ::open("/dev/null", O_RDONLY | O_CLOEXEC)) >= 0;) held.push_back(fd);
      std::cout << "filled " << held.size() << std::endl;
    } else if (line == "release") {
      for (int fd : held) ::close(fd);
      held.clear();
      std::cout << "released" << std::endl;
    } else if (line == "stats") {
      const rp::SceneViewerStatistics s = viewer.getStatistics();
      std::cout << "stats " << s.pages << " " << s.openConnections << " " << s.connectionsClosedForRoom << " "
                << s.connectionsRefused << " " << s.acceptFailures << std::endl;
    }
  }
  for (int fd : held) ::close(fd);
  viewer.stop();
  return 0;
}
