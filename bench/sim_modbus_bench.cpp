// Chunks per second `hybridctl sim serve` accepts over Modbus TCP on loopback: one FC23
// request per chunk (121 mailbox registers written, the 46-register status mirror read
// back), time scale 0, against the same FC23 loop on a trivial libmodbus server (receive,
// reply, nothing else) in the same run. Client and both servers are pinned to CPU 0 (on
// these 2-vCPU machines unpinned loopback round trips swing 4x; see ../shared/PEERS.md),
// so the ratio of the two figures is the number to compare across machines.
//
//   scripts/build -DHYBRIDCTL_BUILD_BENCH=ON && build/bench/sim_modbus_bench

#include <benchmark/benchmark.h>

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include <arpa/inet.h>
#include <modbus/modbus.h>
#include <netinet/in.h>
#include <sys/wait.h>
#include <unistd.h>

#include "bench/bench_main.hpp"
#include "bench/bench_process.hpp"
#include "protocol/chunk.hpp"
#include "protocol/messages.hpp"
#include "protocol/modbus_map.hpp"

namespace {

namespace mb = hybridctl::protocol::modbus;
using namespace hybridctl::protocol;

using hybridctl::bench::ChildProcess;
using hybridctl::bench::pin_to_cpu;

// A libmodbus server that only receives and replies (the baseline), pinned, in a child.
void start_bare_server(ChildProcess& child) {
  modbus_t* ctx = modbus_new_tcp("127.0.0.1", 0);
  const int listen_fd = modbus_tcp_listen(ctx, 1);
  sockaddr_in addr{};
  socklen_t len = sizeof addr;
  ::getsockname(listen_fd, reinterpret_cast<sockaddr*>(&addr), &len);
  child.port = ntohs(addr.sin_port);
  child.pid = ::fork();
  if (child.pid == 0) {
    pin_to_cpu(0);
    modbus_mapping_t* map = modbus_mapping_new_start_address(0, 0, 0, 0, 0, mb::kHoldingRegisterCount, 0, mb::kInputRegisterCount);
    for (;;) {
      int fd = listen_fd;
      if (modbus_tcp_accept(ctx, &fd) < 0) _exit(1);
      std::uint8_t query[MODBUS_TCP_MAX_ADU_LENGTH];
      for (;;) {
        const int rc = modbus_receive(ctx, query);
        if (rc < 0) break;
        if (rc > 0) modbus_reply(ctx, query, rc, map);
      }
      modbus_close(ctx);
    }
  }
  ::close(listen_fd);
  modbus_free(ctx);
}

modbus_t* connect(int port) {
  modbus_t* ctx = modbus_new_tcp("127.0.0.1", port);
  modbus_set_response_timeout(ctx, 2, 0);
  if (modbus_connect(ctx) != 0) throw std::runtime_error("connect: " + std::string(modbus_strerror(errno)));
  return ctx;
}

// A long program of short feed moves inside the example machine's envelope. No M2 at the
// end: the benchmark sets the program again when it ran out, and the simulated controller
// keeps the interpreter's "program ended" state across SET_PROGRAM (noted for its owner).
std::vector<std::string> program(int moves) {
  std::string p = "G21 G90 G17\nG54\nT1 M6\nS8000 M3\nG0 X0 Y0 Z20\n";
  for (int i = 0; i < moves; ++i) p += "G1 X" + std::to_string(i % 50) + " Y" + std::to_string(i % 30) + " Z20 F1200\n";
  return program_lines(p);
}

double g_sim_rate = 0, g_bare_rate = 0;
int g_moves = 400000;  // 2,000 for --smoke

void BM_SimulatorChunksFc23(benchmark::State& state) {
  ChildProcess sim = hybridctl::bench::start_simulator({"--modbus", "tcp://127.0.0.1:0"}, "modbus-tcp");
  pin_to_cpu(0);
  modbus_t* ctx = connect(sim.port);
  const std::vector<std::string> lines = program(g_moves);
  const std::uint64_t identity = program_identity(lines);
  std::uint16_t command_seq = 0;
  auto command = [&](CommandCode code) {
    Command c;
    c.code = code;
    c.seq = ++command_seq;
    c.identity = identity;
    c.line_count = static_cast<std::uint32_t>(lines.size());
    const CommandRegisters regs = encode_command(c);
    modbus_write_registers(ctx, mb::kCommandAddress, mb::kCommandCount, regs.data());
  };
  command(CommandCode::SetProgram);
  command(CommandCode::Start);
  std::uint32_t seq = 1, line = 1;
  std::uint64_t accepted = 0, buffer_full = 0;
  std::uint16_t status[mb::kStatusCount];
  for (auto _ : state) {
    if (line > lines.size()) {  // the program is done: start it again
      state.PauseTiming();
      command(CommandCode::SetProgram);
      command(CommandCode::Start);
      seq = line = 1;
      state.ResumeTiming();
    }
    const auto chunk = make_chunk(lines, line, seq, identity, mb::kMaxChunkPayload);
    const auto regs = mb::encode_mailbox(*chunk);
    if (modbus_write_and_read_registers(ctx, mb::kMailboxAddress, int(regs->size()), regs->data(),
                                        mb::kStatusMirrorAddress, mb::kStatusCount, status) != int(mb::kStatusCount)) {
      state.SkipWithError(modbus_strerror(errno));
      break;
    }
    const auto result = static_cast<ResultCode>(status[status_reg::kChunkResult]);
    if (result == ResultCode::Accepted) {
      ++accepted;
      ++seq;
      line += chunk->line_count;
    } else if (result == ResultCode::BufferFull) {
      ++buffer_full;  // the controller has not executed enough yet: write it again
    } else {
      const auto st = static_cast<ControllerState>(status[status_reg::kState]);
      const auto alarm = static_cast<AlarmCode>(status[status_reg::kAlarm]);
      state.SkipWithError(("chunk " + std::to_string(seq) + " refused: " + std::string(to_string(result)) + " in state " +
                           std::string(to_string(st)) + ", alarm " + std::string(to_string(alarm)))
                              .c_str());
      break;
    }
  }
  state.counters["chunks/s"] = benchmark::Counter(double(accepted), benchmark::Counter::kIsRate);
  state.counters["buffer_full"] = double(buffer_full);
  state.SetItemsProcessed(static_cast<std::int64_t>(accepted));
  modbus_close(ctx);
  modbus_free(ctx);
}

void BM_BareLibmodbusFc23(benchmark::State& state) {
  ChildProcess bare;
  start_bare_server(bare);
  pin_to_cpu(0);
  modbus_t* ctx = connect(bare.port);
  const std::vector<std::uint16_t> regs(mb::kMailboxRegisters, 0x4731);
  std::uint16_t status[mb::kStatusCount];
  std::uint64_t done = 0;
  for (auto _ : state) {
    if (modbus_write_and_read_registers(ctx, mb::kMailboxAddress, int(regs.size()), regs.data(),
                                        mb::kStatusMirrorAddress, mb::kStatusCount, status) != int(mb::kStatusCount)) {
      state.SkipWithError(modbus_strerror(errno));
      break;
    }
    ++done;
  }
  state.counters["requests/s"] = benchmark::Counter(double(done), benchmark::Counter::kIsRate);
  state.SetItemsProcessed(static_cast<std::int64_t>(done));
  modbus_close(ctx);
  modbus_free(ctx);
}

// Keeps each benchmark's items/s for the ratio printed at the end.
class RateReporter : public hybridctl::bench::CheckingReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& r : runs) {
      const auto it = r.counters.find("items_per_second");
      if (it == r.counters.end() || r.error_occurred) continue;
      const std::string name = r.benchmark_name();
      if (name.find("Simulator") != std::string::npos) g_sim_rate = it->second;
      if (name.find("Bare") != std::string::npos) g_bare_rate = it->second;
    }
    CheckingReporter::ReportRuns(runs);
  }
};

}  // namespace

BENCHMARK(BM_BareLibmodbusFc23)->MinTime(2.0)->UseRealTime();
BENCHMARK(BM_SimulatorChunksFc23)->MinTime(2.0)->UseRealTime();

namespace {

// --smoke: 300 chunks each way on a program of 2,000 lines.
void register_smoke_cases() {
  g_moves = 2000;
  hybridctl::bench::smoke_case("BM_BareLibmodbusFc23", BM_BareLibmodbusFc23)->Iterations(300);
  hybridctl::bench::smoke_case("BM_SimulatorChunksFc23", BM_SimulatorChunksFc23)->Iterations(300);
}

}  // namespace

int main(int argc, char** argv) {
  std::signal(SIGPIPE, SIG_IGN);
  RateReporter reporter;
  const int status = hybridctl::bench::run_benchmarks(argc, argv, register_smoke_cases, &reporter);
  if (g_sim_rate > 0 && g_bare_rate > 0) {
    std::printf("\nsimulator / bare libmodbus FC23 (both pinned to CPU %d): %.0f / %.0f requests/s = %.2f\n", hybridctl::bench::kBenchCpu,
                g_sim_rate, g_bare_rate, g_sim_rate / g_bare_rate);
  }
  return status;
}
