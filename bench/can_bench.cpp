// Program streaming over CAN through socketcand against `hybridctl sim serve
// --can-bitrate 1000000` (the simulator delivers every frame, both directions, as a
// 1 Mbit/s classic CAN bus would: sim/wire/can_node.hpp, can_frame_time), at time scale 0.
//
// Two figures in the same run, on the same simulated bus:
//  - BM_RawBusFrames: the bus itself. One socketcand client puts 8-byte frames on an
//    identifier no node listens to, back to back; a second client times their arrival.
//    This is the most payload the modelled bus carries (the controller's periodic status
//    snapshots share it, as they do while streaming).
//  - BM_StreamProgram: drivers::stream_program (the code `hybridctl run` uses) streaming a
//    program of ~28-byte feed moves through drivers::CanTransport, with the job journal,
//    from the first status read to the controller's COMPLETED.
// Each reports payload bytes/s; the stream also as a ratio to the raw bus (measured above)
// and to the bus's theoretical payload rate (8 data bytes per 8-byte frame time: 135 bits,
// 59,259 B/s at 1 Mbit/s with the simulator's worst-case bit stuffing). The protocol's
// ceiling is 7/8 of it: ISO-TP consecutive frames carry 7 payload bytes.
//
//   scripts/build -DHYBRIDCTL_BUILD_BENCH=ON && build/bench/can_bench

#include <benchmark/benchmark.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "bench/bench_main.hpp"
#include "bench/bench_process.hpp"
#include "tests/drivers/feed_moves_program.hpp"
#include "drivers/journal.hpp"
#include "protocol/chunk.hpp"
#include "protocol/messages.hpp"
#include "drivers/socketcand_transport.hpp"
#include "drivers/streamer.hpp"
#include "drivers/transport.hpp"
#include "sim/wire/can_node.hpp"

namespace {

using namespace hybridctl;
using Clock = std::chrono::steady_clock;
namespace fs = std::filesystem;

constexpr std::uint32_t kBitrate = 1'000'000;

double theoretical_payload_rate() {
  const auto frame = sim::wire::can_frame_time(8, kBitrate);
  return 8.0 * 1e6 / double(frame.count());
}

const bench::ChildProcess& simulator() {
  static const bench::ChildProcess sim = bench::start_simulator(
      {"--socketcand", "127.0.0.1:0", "--can-bitrate", std::to_string(kBitrate)}, "socketcand");
  return sim;
}

double g_raw_rate = 0;

void BM_RawBusFrames(benchmark::State& state) {
  const int frames = static_cast<int>(state.range(0));
  drivers::SocketcandIo sender("127.0.0.1", simulator().port, "can0");
  drivers::SocketcandIo receiver("127.0.0.1", simulator().port, "can0");
  sender.open(std::chrono::milliseconds(2000));
  receiver.open(std::chrono::milliseconds(2000));
  // socketcand passes frames to a raw-mode client only a moment after its `< ok >`: wait
  // for the first one (the controller's periodic status) before timing anything.
  if (!receiver.receive(Clock::now() + std::chrono::milliseconds(2000))) {
    state.SkipWithError("no frame from the simulated bus");
    return;
  }
  std::vector<protocol::can::CanFrame> batch(64);
  for (auto& f : batch) {
    f.id = 0x7F0;  // no node's identifier (docs/protocol.md, "CAN mapping")
    f.len = 8;
    for (int i = 0; i < 8; ++i) f.data[i] = static_cast<std::uint8_t>(0xA5 ^ i);
  }
  std::uint64_t bytes = 0;
  double seconds = 0;
  for (auto _ : state) {
    const auto start = Clock::now();
    int sent = 0, received = 0;
    while (received < frames) {
      // At most 512 frames in flight: socketcand drops a client that leaves 1 MiB unread.
      const bool can_send = sent < frames && sent - received < 512;
      if (can_send) {
        sender.send(batch);
        sent += static_cast<int>(batch.size());
        continue;
      }
      const auto frame = receiver.receive(Clock::now() + std::chrono::milliseconds(2000));
      if (!frame) {
        state.SkipWithError("frames lost on the simulated bus");
        return;
      }
      if (frame->id == 0x7F0) ++received;
    }
    const double s = std::chrono::duration<double>(Clock::now() - start).count();
    state.SetIterationTime(s);
    seconds += s;
    bytes += 8ull * static_cast<std::uint64_t>(frames);
  }
  g_raw_rate = double(bytes) / seconds;
  state.counters["payload_B/s"] = g_raw_rate;
  state.counters["vs_theory"] = g_raw_rate / theoretical_payload_rate();
}

std::vector<std::string> program(int moves, int run) { return hybridctl::testing::feed_moves_program(moves, "can_bench run " + std::to_string(run)); }

// Where the stream's time goes: the seconds spent inside each kind of transport call.
class TimedTransport final : public drivers::Transport {
 public:
  explicit TimedTransport(drivers::Transport& inner) : inner_(inner) {}
  std::string describe() const override { return inner_.describe(); }
  std::size_t max_chunk_payload() const override { return inner_.max_chunk_payload(); }
  protocol::Status read_status() override { return timed(status_s, [&] { return inner_.read_status(); }); }
  protocol::Status send_command(const protocol::Command& c) override {
    return timed(command_s, [&] { return inner_.send_command(c); });
  }
  protocol::Status send_chunk(const protocol::Chunk& c) override {
    return timed(chunk_s, [&] { return inner_.send_chunk(c); });
  }
  void send_heartbeat(std::uint16_t counter) override { inner_.send_heartbeat(counter); }
  drivers::TransportCounters counters() const override { return inner_.counters(); }

  double status_s = 0, command_s = 0, chunk_s = 0;

 private:
  template <class F>
  protocol::Status timed(double& total, F&& f) {
    const auto start = Clock::now();
    protocol::Status s = f();
    total += std::chrono::duration<double>(Clock::now() - start).count();
    return s;
  }
  drivers::Transport& inner_;
};

void BM_StreamProgram(benchmark::State& state) {
  bench::pin_to_cpu(0);
  auto can = drivers::open_transport("socketcand://127.0.0.1:" + std::to_string(simulator().port) + "/can0");
  TimedTransport transport(*can);
  const fs::path jobs = fs::temp_directory_path() / ("hybridctl-can-bench-" + std::to_string(::getpid()));
  int run = 0;
  std::uint64_t bytes = 0, lines = 0, chunks = 0;
  double seconds = 0;
  for (auto _ : state) {
    state.PauseTiming();
    const auto program_lines = program(static_cast<int>(state.range(0)), ++run);
    std::uint64_t program_bytes = 0;
    for (const auto& l : program_lines) program_bytes += l.size() + 1;  // with its newline
    fs::remove_all(jobs);
    drivers::JournalHeader header;
    header.program = "can_bench";
    header.identity = protocol::program_identity(program_lines);
    header.lines = static_cast<std::uint32_t>(program_lines.size());
    drivers::Journal journal = drivers::Journal::create(jobs, header);
    state.ResumeTiming();

    const auto start = Clock::now();
    const drivers::StreamResult r = drivers::stream_program(transport, program_lines, {}, {}, &journal);
    const double s = std::chrono::duration<double>(Clock::now() - start).count();
    state.SetIterationTime(s);
    if (!r.completed) {
      state.SkipWithError(("the stream stopped: " + r.stopped_because).c_str());
      break;
    }
    seconds += s;
    bytes += program_bytes;
    lines += program_lines.size();
    chunks += r.counters.chunks_accepted;
  }
  fs::remove_all(jobs);
  if (seconds <= 0) return;
  const double rate = double(bytes) / seconds;
  state.counters["payload_B/s"] = rate;
  state.counters["lines/s"] = double(lines) / seconds;
  state.counters["chunks"] = double(chunks) / double(run);
  state.counters["vs_theory"] = rate / theoretical_payload_rate();
  if (g_raw_rate > 0) state.counters["vs_raw_bus"] = rate / g_raw_rate;
  // Shares of the stream's time spent waiting in each kind of call (the rest: the host).
  state.counters["in_chunks"] = transport.chunk_s / seconds;
  state.counters["in_status"] = transport.status_s / seconds;
  state.counters["in_commands"] = transport.command_s / seconds;
}

}  // namespace

// The raw bus first: the stream's ratio to it is computed from its figure.
BENCHMARK(BM_RawBusFrames)->Arg(640 * 64)->Iterations(3)->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_StreamProgram)->Arg(12000)->Iterations(3)->UseManualTime()->Unit(benchmark::kMillisecond);

namespace {

// --smoke: 640 raw frames, then a program of 500 lines streamed once.
void register_smoke_cases() {
  hybridctl::bench::smoke_case("BM_RawBusFrames", BM_RawBusFrames)->Arg(640)->UseManualTime()->Unit(benchmark::kMillisecond);
  hybridctl::bench::smoke_case("BM_StreamProgram", BM_StreamProgram)->Arg(500)->UseManualTime()->Unit(benchmark::kMillisecond);
}

}  // namespace

int main(int argc, char** argv) { return hybridctl::bench::run_benchmarks(argc, argv, register_smoke_cases); }
