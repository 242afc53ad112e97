#pragma once
// The main of every benchmark program, and its smoke mode.
//
//   build/bench/NAME_bench [--benchmark_* flags]   the full run, as Google Benchmark runs it
//   build/bench/NAME_bench --smoke                 the program's smoke cases only: the smallest
//                                                  case of each kind, one iteration, seconds
//
// Each program registers its smoke cases in a function it passes to run_benchmarks
// (named "smoke/..." by smoke_case), so a smoke run goes through the same code as the full
// run on a small input. Exit status: 0 when every case that ran succeeded; 1 when one
// reported an error (SkipWithError; counted with the console output, not with
// --benchmark_format=json|csv), or when --smoke ran no case at all; 2 for an argument
// Google Benchmark does not know. (BENCHMARK_MAIN exits 0 whatever a case
// reported, which is why the programs use this instead.) bench/smoke runs every program
// with --smoke.
//
//   int main(int argc, char** argv) { return hybridctl::bench::run_benchmarks(argc, argv, register_smoke_cases); }

#include <benchmark/benchmark.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

namespace hybridctl::bench {

/// Wall seconds that fn() takes, for benchmarks that time two ways in one run.
template <class Fn>
double seconds_of(Fn&& fn) {
  const auto t0 = std::chrono::steady_clock::now();
  fn();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// A benchmark function and its name, for lists of smoke cases.
using NamedCase = std::pair<const char*, void (*)(benchmark::State&)>;

/// Registers `fn` as the smoke case "smoke/NAME", one iteration. Chain ->Arg() etc. for
/// the case's (small) input, ->Iterations(N) for more.
template <class Fn>
benchmark::internal::Benchmark* smoke_case(const std::string& name, Fn&& fn) {
  return benchmark::RegisterBenchmark(("smoke/" + name).c_str(), std::forward<Fn>(fn))->Iterations(1);
}

/// A console reporter that counts the runs that reported an error. Programs with their own
/// reporter derive from it. Colours only on a terminal (as Google Benchmark's own default),
/// so that scripts can read the table.
class CheckingReporter : public benchmark::ConsoleReporter {
 public:
  CheckingReporter() : ConsoleReporter(::isatty(STDOUT_FILENO) ? OO_Color : OO_None) {}
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& r : runs)
      if (r.error_occurred) {
        ++failed_;
        std::fprintf(stderr, "benchmark %s failed: %s\n", r.benchmark_name().c_str(), r.error_message.c_str());
      }
    ConsoleReporter::ReportRuns(runs);
  }
  int failed() const { return failed_; }

 private:
  int failed_ = 0;
};

/// Parses the arguments (`--smoke` and Google Benchmark's own), runs the benchmarks and
/// returns the exit status (above). `register_smoke` registers the smoke cases; it is only
/// called for --smoke. `reporter`: the display reporter, a CheckingReporter by default.
inline int run_benchmarks(int argc, char** argv, void (*register_smoke)(), CheckingReporter* reporter = nullptr) {
  std::vector<char*> args;
  bool smoke = false, console = true;
  for (int i = 0; i < argc; ++i) {
    if (i > 0 && std::strcmp(argv[i], "--smoke") == 0)
      smoke = true;
    else
      args.push_back(argv[i]);
    if (i > 0 && std::strncmp(argv[i], "--benchmark_format=", 19) == 0 && std::strcmp(argv[i] + 19, "console") != 0)
      console = false;
  }
  int count = static_cast<int>(args.size());
  args.push_back(nullptr);
  benchmark::Initialize(&count, args.data());
  if (benchmark::ReportUnrecognizedArguments(count, args.data())) return 2;
  if (smoke) register_smoke();
  CheckingReporter fallback;
  CheckingReporter* display = reporter ? reporter : &fallback;
  if (!console) {  // --benchmark_format=json|csv: Google Benchmark's own reporter, failures not counted
    const std::size_t ran = smoke ? benchmark::RunSpecifiedBenchmarks("^smoke/") : benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return smoke && ran == 0 ? 1 : 0;
  }
  const std::size_t ran = smoke ? benchmark::RunSpecifiedBenchmarks(display, "^smoke/")
                                : benchmark::RunSpecifiedBenchmarks(display);
  benchmark::Shutdown();
  if (smoke && ran == 0) {
    std::fprintf(stderr, "%s --smoke: no smoke case ran\n", argv[0]);
    return 1;
  }
  if (display->failed() > 0) {
    std::fprintf(stderr, "%s: %d benchmark(s) failed\n", argv[0], display->failed());
    return 1;
  }
  return 0;
}

}  // namespace hybridctl::bench
