// Streaming a job with its record in the cell's database (cell::StreamJournal, what `cell
// machine-host` uses) against the same stream with the job journal file (what `hybridctl
// run` uses), in the same process, on the same `hybridctl sim serve` over Modbus TCP at
// time scale 0 and a PostgreSQL server of the bench's own on 127.0.0.1
// (tests/cell/postgres_server.hpp). The two alternate, iteration by iteration; counters
// lines/s for each and their ratio (the issue asks at least 0.9).
//
//   BUILD_TARGET=cell_stream_bench scripts/build -DHYBRIDCTL_BUILD_BENCH=ON
//   build/bench/cell_stream_bench
//   build/bench/cell_stream_bench --smoke   (a 500-line program, once each)
#include <benchmark/benchmark.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "bench/bench_cell.hpp"
#include "bench/bench_main.hpp"
#include "bench/bench_process.hpp"
#include "tests/drivers/feed_moves_program.hpp"
#include "cell/database.hpp"
#include "cell/stream_journal.hpp"
#include "cell/streams.hpp"
#include "drivers/journal.hpp"
#include "drivers/streamer.hpp"
#include "drivers/transport.hpp"
#include "protocol/chunk.hpp"

namespace {

using namespace hybridctl;
using Clock = std::chrono::steady_clock;
namespace fs = std::filesystem;

const bench::ChildProcess& simulator() {
  static const bench::ChildProcess sim = bench::start_simulator({"--modbus", "tcp://127.0.0.1:0"}, "modbus-tcp");
  return sim;
}

// The cell's server, with a host's lease on its machine.
cell::testing::PostgresServer& server() {
  static cell::testing::PostgresServer& s = bench::cell_server();
  static const bool leased = [] {
    cell::Database db(s.uri());
    return cell::take_machine(db, "mill", "bench", 3600).ours;
  }();
  if (!leased) throw std::runtime_error("the bench's host did not get the machine's lease");
  return s;
}

std::vector<std::string> program(int moves, int run) { return hybridctl::testing::feed_moves_program(moves, "cell_stream_bench run " + std::to_string(run)); }

// A planned job bound to the machine with `lines` as its program, as the host binds one.
std::int64_t bound_job(cell::Database& db, const std::vector<std::string>& lines) {
  const cell::Rows id = db.exec("a planned job",
                                "INSERT INTO cell_jobs (machine, part_name, part, machine_text, machine_hash, state) "
                                "VALUES ('mill', 'bench.stl', '', 'name: mill', '0', 'planned') RETURNING id");
  const std::int64_t job = id.number(0, 0);
  if (!cell::bind_job(db, job, "mill", "bench", 1, protocol::program_text(lines))) throw std::runtime_error("not bound");
  return job;
}

struct Rates {
  double file_s = 0, database_s = 0;
  std::uint64_t file_lines = 0, database_lines = 0;
};

double stream_once(drivers::Transport& transport, const std::vector<std::string>& lines, drivers::JobRecord& record) {
  const auto start = Clock::now();
  const drivers::StreamResult r = drivers::stream_program(transport, lines, {}, {}, &record);
  const double s = std::chrono::duration<double>(Clock::now() - start).count();
  if (!r.completed) throw std::runtime_error("the stream stopped: " + r.stopped_because);
  return s;
}

void BM_StreamWithDatabaseRecord(benchmark::State& state) {
  auto transport = drivers::open_transport("modbus-tcp://127.0.0.1:" + std::to_string(simulator().port));
  cell::Database db(server().uri());
  const fs::path jobs = fs::temp_directory_path() / ("hybridctl-cell-stream-bench-" + std::to_string(::getpid()));
  int run = 0;
  Rates rates;
  for (auto _ : state) {
    // The file journal first, as `run` streams it.
    state.PauseTiming();
    const auto file_lines = program(int(state.range(0)), ++run);
    fs::remove_all(jobs);
    drivers::JournalHeader header;
    header.program = "cell_stream_bench";
    header.identity = protocol::program_identity(file_lines);
    header.lines = std::uint32_t(file_lines.size());
    double file_s = 0;
    {
      drivers::Journal journal = drivers::Journal::create(jobs, header);
      file_s = stream_once(*transport, file_lines, journal);
    }
    // Then the database's record, as `cell machine-host` streams it.
    const auto db_lines = program(int(state.range(0)), ++run);
    const std::int64_t job = bound_job(db, db_lines);
    state.ResumeTiming();
    double db_s = 0;
    {
      cell::StreamJournal journal({server().uri(), job, "mill", "bench", 3600, {}}, {});
      db_s = stream_once(*transport, db_lines, journal);
    }
    state.SetIterationTime(db_s);
    rates.file_s += file_s;
    rates.database_s += db_s;
    rates.file_lines += file_lines.size();
    rates.database_lines += db_lines.size();
  }
  fs::remove_all(jobs);
  if (rates.file_s <= 0 || rates.database_s <= 0) return;
  const double file_rate = double(rates.file_lines) / rates.file_s, db_rate = double(rates.database_lines) / rates.database_s;
  state.counters["file_lines/s"] = file_rate;
  state.counters["database_lines/s"] = db_rate;
  state.counters["ratio"] = db_rate / file_rate;
}

}  // namespace

BENCHMARK(BM_StreamWithDatabaseRecord)->Arg(20000)->Iterations(5)->UseManualTime()->Unit(benchmark::kMillisecond);

namespace {

void register_smoke_cases() {
  hybridctl::bench::smoke_case("BM_StreamWithDatabaseRecord", BM_StreamWithDatabaseRecord)
      ->Arg(500)
      ->UseManualTime()
      ->Unit(benchmark::kMillisecond);
}

}  // namespace

int main(int argc, char** argv) { return hybridctl::bench::run_benchmarks(argc, argv, register_smoke_cases); }
