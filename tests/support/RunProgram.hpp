// Shared by the tests that run a program as a user does (rp-plan, rp-calibrate): its exit status
// and what it printed.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace rp::test {

// What a program run left: its exit status (-1 if it did not exit) and its stdout and stderr.
struct Outcome {
  int status = -1;
  std::string out, err;
};

// The numbers that follow the first `word` in `text` (a program's "final 0.1 0.2 ..." line), up
// to the first thing that is not a number; empty if `word` does not occur.
inline std::vector<double> numbersAfter(const std::string& text, const std::string& word) {
  std::vector<double> v;
  const std::size_t at = text.find(word);
  if (at == std::string::npos) return v;
  std::istringstream in(text.substr(at + word.size()));
  for (double x; in >> x;) v.push_back(x);
  return v;
}

// The whole file at `path` ("" if it cannot be read).
inline std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Runs `command` (a shell command line) with stdout and stderr to `base`.out and `base`.err,
// which are removed again once read.
inline Outcome runProgram(const std::string& command, const std::string& base) {
  const int raw = std::system((command + " >" + base + ".out 2>" + base + ".err").c_str());
  Outcome r;
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  r.out = slurp(base + ".out");
  r.err = slurp(base + ".err");
  std::remove((base + ".out").c_str());
  std::remove((base + ".err").c_str());
  return r;
}

// Runs `command` (a shell command line) and returns what it printed (stdout and stderr merged,
// in order) and its exit status (-1 if it did not exit).
inline std::pair<std::string, int> runMerged(const std::string& command) {
  FILE* p = popen((command + " 2>&1").c_str(), "r");
  if (!p) return {"popen failed", -1};
  std::string out;
  char buffer[4096];
  while (std::fgets(buffer, sizeof buffer, p)) out += buffer;
  const int status = pclose(p);
  return {out, WIFEXITED(status) ? WEXITSTATUS(status) : -1};
}

}  // namespace rp::test
