// A program started with fork/exec for the ROS 2 tests, its stdout and stderr on a pipe: read line
// by line while it runs, then its exit status. The destructor kills one still running.
#pragma once

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <string>
#include <vector>

namespace rp::test {

struct Child {
  pid_t pid = -1;
  int fd = -1;
  std::string buffered;

  explicit Child(const std::vector<std::string>& argv) {
    int p[2];
    if (pipe(p) != 0) return;
    pid = fork();
    if (pid == 0) {
      dup2(p[1], 1);
      dup2(p[1], 2);
      close(p[0]);
      close(p[1]);
      std::vector<char*> args;
      for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
      args.push_back(nullptr);
      execv(args[0], args.data());
      _exit(127);
    }
    close(p[1]);
    fd = p[0];
  }
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;
  ~Child() {
    if (pid > 0) {
      kill(pid, SIGKILL);
      waitpid(pid, nullptr, 0);
    }
    if (fd >= 0) close(fd);
  }
  // The next line of output ("" at the end).
  std::string line() {
    for (;;) {
      if (const std::size_t nl = buffered.find('\n'); nl != std::string::npos) {
        std::string l = buffered.substr(0, nl);
        buffered.erase(0, nl + 1);
        return l;
      }
      char b[512];
      const ssize_t n = read(fd, b, sizeof b);
      if (n <= 0) {
        std::string rest;
        rest.swap(buffered);
        return rest;
      }
      buffered.append(b, static_cast<std::size_t>(n));
    }
  }
  // Every line until the end, then the exit status (-1: not exited normally).
  int finish(std::string& output) {
    for (std::string l = line(); !l.empty() || !buffered.empty(); l = line()) {
      output.append(l);
      output.push_back('\n');
    }
    int status = 0;
    waitpid(pid, &status, 0);
    pid = -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }
};

}  // namespace rp::test
