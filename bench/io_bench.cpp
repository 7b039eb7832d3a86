// Cost of the cyclic I/O calls a servo loop makes: a simulated board, a hardware-server client
// (shared memory, the server running in this process), and decoding an RDT record.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <string>

#include "rp/io/HwServer.hpp"
#include "rp/io/HwServerIoBoard.hpp"
#include "rp/io/NetFtClient.hpp"
#include "rp/io/SimulatedIoBoard.hpp"

namespace {

// One servo cycle's worth of I/O: 6 encoders in, 6 analog outputs, 2 digital outputs.
void cycle(rp::IoBoard& board, int i) {
  std::int64_t counts = 0;
  for (int e = 0; e < 6; ++e) board.readEncoder(e, counts);
  for (int a = 0; a < 6; ++a) board.writeAnalogOutput(a, 0.001 * (i & 1023));
  board.writeDigitalOutput(0, (i & 1) != 0);
  board.writeDigitalOutput(1, (i & 2) != 0);
  benchmark::DoNotOptimize(counts);
}

void BM_SimulatedIoBoardCycle(benchmark::State& state) {
  rp::SimulatedIoBoard board;
  int i = 0;
  for (auto _ : state) cycle(board, ++i);
}
BENCHMARK(BM_SimulatedIoBoardCycle);

void BM_HwServerIoBoardCycle(benchmark::State& state) {
  rp::SimulatedIoBoard board;
  rp::HwServer server(board, "bench-" + std::to_string(::getpid()), 1000.0);
  server.start();
  rp::HwServerIoBoard client(server.name());
  int i = 0;
  for (auto _ : state) cycle(client, ++i);
  server.stop();
}
BENCHMARK(BM_HwServerIoBoardCycle);

void BM_NetFtDecode(benchmark::State& state) {
  const std::uint8_t bytes[36] = {0, 0, 0, 1, 0, 0, 0x1F, 0x40, 0, 0, 0, 0, 0, 0x0F, 0x42, 0x40, 0xFF, 0xF0,
                                  0xBD, 0xC0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0x01, 0x86, 0xA0};
  for (auto _ : state) benchmark::DoNotOptimize(rp::NetFtClient::decode(bytes, 1e6, 1e6));
}
BENCHMARK(BM_NetFtDecode);

}  // namespace

BENCHMARK_MAIN();
