// The host's Modbus TCP transport (drivers/modbus_transport.hpp) on loopback against
// `hybridctl sim serve` at time scale 0: chunks of up to 222 payload bytes (~8 lines of
// ~28 bytes) sent with ModbusTransport::send_chunk (one FC23 request: mailbox written,
// status mirror read), against a bare libmodbus FC23 loop sending the same chunks to the
// same simulator in the same run. The simulator and this process are pinned to CPU 0 (on
// these 2-vCPU machines unpinned loopback round trips swing 4x; ../shared/PEERS.md), so the
// ratio of the two figures is the number to compare across machines: what the transport
// (status decoding, error handling, counters) costs over libmodbus itself.
//
//   scripts/build -DHYBRIDCTL_BUILD_BENCH=ON && build/bench/transport_bench

#include <benchmark/benchmark.h>

#include <modbus/modbus.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench/bench_process.hpp"
#include "protocol/chunk.hpp"
#include "protocol/messages.hpp"
#include "protocol/modbus_map.hpp"
#include "drivers/transport.hpp"
#include "bench/bench_main.hpp"

namespace {

namespace mb = hybridctl::protocol::modbus;
using namespace hybridctl;
using namespace hybridctl::protocol;

const bench::ChildProcess& simulator() {
  static const bench::ChildProcess sim = bench::start_simulator({"--modbus", "tcp://127.0.0.1:0"}, "modbus-tcp");
  return sim;
}

// ~28-byte feed moves inside the example machine's travel. No M2: the benchmark sets the
// program again when it ran out (the simulated controller keeps an ended interpreter
// across SET_PROGRAM).
std::vector<std::string> program(int moves) {
  std::string p = "G21 G90 G17\nG54\nT1 M6\nS8000 M3\nG0 X0 Y0 Z20\n";
  char line[64];
  for (int i = 0; i < moves; ++i) {
    std::snprintf(line, sizeof line, "G1 X%.3f Y%.3f Z20 F1200\n", 10 + (i * 7919LL % 40000) / 1000.0,
                  10 + (i * 104729LL % 20000) / 1000.0);
    p += line;
  }
  return program_lines(p);
}

int g_moves = 200000;  // 2,000 for --smoke

const std::vector<std::string>& lines() {
  static const std::vector<std::string> l = program(g_moves);
  return l;
}

// The chunks of the program, made once (both loops send the same ones).
const std::vector<Chunk>& chunks() {
  static const std::vector<Chunk> c = [] {
    std::vector<Chunk> out;
    const std::uint64_t identity = program_identity(lines());
    std::uint32_t line = 1;
    for (std::uint32_t seq = 1; line <= lines().size(); ++seq) {
      out.push_back(*make_chunk(lines(), line, seq, identity, mb::kMaxChunkPayload));
      line += out.back().line_count;
    }
    return out;
  }();
  return c;
}

struct Rates {
  double requests = 0;
  double lines = 0;
};
Rates g_transport, g_bare;

// One benchmark loop over a "send the chunk, get the status" function.
// `command(code, seq)` sends a command. The program is (re)set before the loop and
// whenever it ran out (ABORT first: the other loop may have left it running).
template <class Send, class Command>
void chunk_loop(benchmark::State& state, Send&& send, Command&& command) {
  const auto& cs = chunks();
  std::uint16_t command_seq = 0;
  command(CommandCode::Abort, ++command_seq);
  command(CommandCode::SetProgram, ++command_seq);
  command(CommandCode::Start, ++command_seq);
  std::size_t next = 0;
  std::uint64_t requests = 0, lines_sent = 0, buffer_full = 0;
  for (auto _ : state) {
    if (next == cs.size()) {  // the program is done: set it again
      state.PauseTiming();
      command(CommandCode::Abort, ++command_seq);
      command(CommandCode::SetProgram, ++command_seq);
      command(CommandCode::Start, ++command_seq);
      next = 0;
      state.ResumeTiming();
    }
    const Chunk& chunk = cs[next];
    const Status s = send(chunk);
    ++requests;
    if (s.last_written_chunk == chunk.seq &&
        (s.chunk_result == ResultCode::Accepted || s.chunk_result == ResultCode::Duplicate)) {
      lines_sent += chunk.line_count;
      ++next;
    } else if (s.chunk_result == ResultCode::BufferFull) {
      ++buffer_full;  // the controller has not executed enough yet: send it again
    } else {
      state.SkipWithError(("chunk " + std::to_string(chunk.seq) + ": " + std::string(to_string(s.chunk_result)) +
                           " in state " + std::string(to_string(s.state)))
                              .c_str());
      break;
    }
  }
  state.counters["requests/s"] = benchmark::Counter(double(requests), benchmark::Counter::kIsRate);
  state.counters["lines/s"] = benchmark::Counter(double(lines_sent), benchmark::Counter::kIsRate);
  state.counters["buffer_full"] = double(buffer_full);
  state.SetItemsProcessed(static_cast<std::int64_t>(requests));
}

void BM_TransportSendChunk(benchmark::State& state) {
  bench::pin_to_cpu(0);
  auto t = drivers::open_transport("modbus-tcp://127.0.0.1:" + std::to_string(simulator().port));
  const std::uint64_t identity = program_identity(lines());
  chunk_loop(
      state, [&](const Chunk& c) { return t->send_chunk(c); },
      [&](CommandCode code, std::uint16_t seq) {
        t->send_command(Command{code, static_cast<std::uint16_t>(seq + 1000), code == CommandCode::SetProgram ? identity : 0,
                                code == CommandCode::SetProgram ? static_cast<std::uint32_t>(lines().size()) : 0u});
      });
  const auto c = t->counters();
  state.counters["retries"] = double(c.retries);
}

void BM_BareLibmodbusFc23(benchmark::State& state) {
  bench::pin_to_cpu(0);
  modbus_t* ctx = modbus_new_tcp("127.0.0.1", simulator().port);
  modbus_set_response_timeout(ctx, 2, 0);
  if (modbus_connect(ctx) != 0) {
    state.SkipWithError(modbus_strerror(errno));
    modbus_free(ctx);
    return;
  }
  const std::uint64_t identity = program_identity(lines());
  // Encoded once per chunk, outside the loop: the baseline is libmodbus alone.
  std::vector<std::vector<std::uint16_t>> mailboxes;
  for (const Chunk& c : chunks()) mailboxes.push_back(*mb::encode_mailbox(c));
  std::uint16_t regs[mb::kStatusCount];
  chunk_loop(
      state,
      [&](const Chunk& c) {
        const auto& m = mailboxes[c.seq - 1];
        Status s;
        if (modbus_write_and_read_registers(ctx, mb::kMailboxAddress, int(m.size()), m.data(), mb::kStatusMirrorAddress,
                                            mb::kStatusCount, regs) != int(mb::kStatusCount))
          return s;  // reported by the loop as an unexpected result
        // The two fields the loop needs, straight from the registers.
        s.chunk_result = static_cast<ResultCode>(regs[status_reg::kChunkResult]);
        s.last_written_chunk = (std::uint32_t(regs[status_reg::kLastWrittenChunk]) << 16) |
                               regs[status_reg::kLastWrittenChunk + 1];
        return s;
      },
      [&](CommandCode code, std::uint16_t seq) {
        const CommandRegisters r =
            encode_command(Command{code, static_cast<std::uint16_t>(seq + 2000), code == CommandCode::SetProgram ? identity : 0,
                                   code == CommandCode::SetProgram ? static_cast<std::uint32_t>(lines().size()) : 0u});
        modbus_write_registers(ctx, mb::kCommandAddress, mb::kCommandCount, r.data());
      });
  modbus_close(ctx);
  modbus_free(ctx);
}

// Keeps each benchmark's rates for the ratio printed at the end.
class RateReporter : public hybridctl::bench::CheckingReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& r : runs) {
      if (r.error_occurred) continue;
      Rates* rates = r.benchmark_name().find("Transport") != std::string::npos ? &g_transport : &g_bare;
      if (auto it = r.counters.find("requests/s"); it != r.counters.end()) rates->requests = it->second;
      if (auto it = r.counters.find("lines/s"); it != r.counters.end()) rates->lines = it->second;
    }
    CheckingReporter::ReportRuns(runs);
  }
};

}  // namespace

BENCHMARK(BM_BareLibmodbusFc23)->MinTime(2.0)->UseRealTime();
BENCHMARK(BM_TransportSendChunk)->MinTime(2.0)->UseRealTime();

namespace {

// --smoke: 300 chunks each way on a program of 2,000 lines.
void register_smoke_cases() {
  g_moves = 2000;
  hybridctl::bench::smoke_case("BM_BareLibmodbusFc23", BM_BareLibmodbusFc23)->Iterations(300);
  hybridctl::bench::smoke_case("BM_TransportSendChunk", BM_TransportSendChunk)->Iterations(300);
}

}  // namespace

int main(int argc, char** argv) {
  std::signal(SIGPIPE, SIG_IGN);
  RateReporter reporter;
  const int status = hybridctl::bench::run_benchmarks(argc, argv, register_smoke_cases, &reporter);
  if (g_transport.requests > 0 && g_bare.requests > 0) {
    std::printf("\nModbusTransport::send_chunk / bare libmodbus FC23, same simulator, both pinned to CPU %d:\n", hybridctl::bench::kBenchCpu);
    std::printf("  %.0f / %.0f requests/s = %.2f\n", g_transport.requests, g_bare.requests,
                g_transport.requests / g_bare.requests);
    std::printf("  %.0f / %.0f lines/s (~28-byte lines, chunks up to 222 bytes)\n", g_transport.lines, g_bare.lines);
  }
  return status;
}
