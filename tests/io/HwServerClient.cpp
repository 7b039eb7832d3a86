// A client program of the hardware server for the watchdog tests (HwServer_test): attaches to the
// server NAME, switches digital output 0 (the amplifier enable) on and writes VOLTS to every analog
// output, prints "ready", then ends the way MODE says:
//   loop       keeps writing the same outputs every millisecond until killed (SIGKILL, SIGTERM,
//              SIGINT: default actions) or stopped (SIGSTOP); prints "refused: MESSAGE" once if
//              the server refuses its writes (it was cut off by the watchdog)
//   idle       keeps the outputs and does nothing more (a servo loop that hangs)
//   background like idle, with a background heartbeat (HwServerIoBoard::Heartbeat::kBackgroundThread)
//   return     returns from main normally (the client's destructor detaches it)
//   exit       _exit(0) after the writes: no destructor, no cleanup
//   throw      an uncaught exception (std::terminate, SIGABRT)
// return, exit and throw wait for SIGUSR1 after "ready", so that the test sees the outputs on first.
// Exit status 2 for bad arguments, 1 if the server cannot be reached.
#include <signal.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>

#include "rp/io/HwServerIoBoard.hpp"
#include "rp/io/IoException.hpp"

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: io_hwserver_client NAME VOLTS loop|idle|background|return|exit|throw\n");
    return 2;
  }
  const std::string name = argv[1], mode = argv[3];
  const double volts = std::atof(argv[2]);
  sigset_t go;
  sigemptyset(&go);
  sigaddset(&go, SIGUSR1);
  pthread_sigmask(SIG_BLOCK, &go, nullptr);  // delivered by sigwait below only
  try {
    rp::HwServerIoBoard board(name, 2000,
                              mode == "background" ? rp::HwServerIoBoard::Heartbeat::kBackgroundThread
                                                   : rp::HwServerIoBoard::Heartbeat::kOperations);
    auto writeAll = [&]() {
      rp::IoStatus s = board.writeDigitalOutput(0, true);
      for (int i = 0; i < board.numAnalogOutputs() && s == rp::IoStatus::kOk; ++i)
        s = board.writeAnalogOutput(i, volts);
      return s;
    };
    if (writeAll() != rp::IoStatus::kOk || board.confirmWrites(5000) != rp::IoStatus::kOk) {
      std::fprintf(stderr, "io_hwserver_client: %s\n", board.lastError());
      return 1;
    }
    std::printf("ready\n");
    std::fflush(stdout);
    if (mode == "loop") {
      bool reported = false;
      while (true) {
        if (writeAll() != rp::IoStatus::kOk && !reported) {
          std::printf("refused: %s\n", board.lastError());
          std::fflush(stdout);
          reported = true;
        }
        ::usleep(1000);
      }
    }
    if (mode == "idle" || mode == "background") {
      while (true) ::pause();
    }
    int sig = 0;
    sigwait(&go, &sig);
    if (mode == "exit") ::_exit(0);
    if (mode == "throw") throw std::runtime_error("calculate() failed");
    if (mode != "return") return 2;
  } catch (const rp::IoException& e) {
    std::fprintf(stderr, "io_hwserver_client: %s\n", e.what());
    return 1;
  }
  return 0;
}
