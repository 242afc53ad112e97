// The shop cell's queue alone (docs/cell.md): N jobs submitted, then claimed and finished
// with a small plan.json by W workers, each on its own connection, as `cell plan-worker`
// does it but without planning: the queue's own cost per job, on a PostgreSQL server of
// the bench's own on 127.0.0.1 (tests/cell/postgres_server.hpp). Each case runs the same
// jobs with one worker first, in the same process: counters jobs per minute with 1 and
// with W workers and their ratio. For scale, the smallest real job (a box at 2 mm voxels)
// plans in about 0.4 s, 150 per minute per core.
//
//   BUILD_TARGET=cell_queue_bench scripts/build -DHYBRIDCTL_BUILD_BENCH=ON
//   build/bench/cell_queue_bench
//   build/bench/cell_queue_bench --smoke   (20 jobs, 2 workers)
#include <benchmark/benchmark.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "bench/bench_cell.hpp"
#include "bench/bench_main.hpp"
#include "cell/jobs.hpp"

namespace {

using namespace hybridctl;

cell::testing::PostgresServer& server() { return bench::cell_server(); }

// Seconds for `workers` to claim and finish every queued job.
double drain(int workers) {
  std::atomic<int> done{0};
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<std::thread> threads;
  for (int w = 0; w < workers; ++w)
    threads.emplace_back([w, &done] {
      cell::Database db(server().uri());
      const std::string name = "bench-" + std::to_string(w);
      cell::Outcome planned;
      planned.state = cell::JobState::Planned;
      planned.files = {{"plan.json", std::string(4096, ' ')}};
      while (const auto job = cell::claim_next(db, name, 30, 2)) {
        if (cell::finish(db, job->job, name, planned)) ++done;
      }
    });
  for (std::thread& t : threads) t.join();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void submit_jobs(int jobs) {
  cell::Database db(server().uri());
  db.exec("the bench's reset", "TRUNCATE cell_jobs CASCADE");
  cell::Submission s;
  s.machine = "mill";
  s.part_name = "box.stl";
  s.part_stl = std::string(684, 'x');  // a box's size in STL
  for (int k = 0; k < jobs; ++k) cell::submit(db, s);
}

void queue_throughput(benchmark::State& state) {
  const int jobs = int(state.range(0)), workers = int(state.range(1));
  double one = 0, many = 0;
  for (auto _ : state) {
    submit_jobs(jobs);
    one += drain(1);
    submit_jobs(jobs);
    many += drain(workers);
    state.SetIterationTime(many);
  }
  const double n = double(jobs) * double(state.iterations());
  state.counters["jobs_per_min_1_worker"] = 60 * n / one;
  state.counters["jobs_per_min"] = 60 * n / many;
  state.counters["ratio_to_1_worker"] = one / many;
}

BENCHMARK(queue_throughput)->Args({200, 4})->Args({1000, 4})->Iterations(1)->UseManualTime()->Unit(benchmark::kMillisecond);

void register_smoke_cases() {
  hybridctl::bench::smoke_case("queue_throughput", queue_throughput)->Args({20, 2})->UseManualTime()->Unit(benchmark::kMillisecond);
}

}  // namespace

int main(int argc, char** argv) { return hybridctl::bench::run_benchmarks(argc, argv, register_smoke_cases); }
