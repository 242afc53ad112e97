// What exact verification (verification/, docs/verification.md) adds to validating a plan:
// each bundled part is planned once by the search alone (plans that exact verification
// may refuse are timed too), then every plan is executed from the raw stock on the voxels
// alone and with exact verification, in the same process, one after the other. Counters: seconds per plan both ways and the
// ratio of what exact verification adds to the voxel validation (aim: at most 1).
//
//   BUILD_TARGET=exact_verification_bench scripts/build -DHYBRIDCTL_BUILD_BENCH=ON
//   build/bench/exact_verification_bench
//   build/bench/exact_verification_bench --smoke   (the flanged hub's best plan alone)
#include <benchmark/benchmark.h>

#include <chrono>
#include <memory>
#include <string>

#include "config/machine_loader.hpp"
#include "geometry/mesh.hpp"
#include "planner/pipeline/plan_report.hpp"
#include "planner/pipeline/planning.hpp"
#include "validation/execution.hpp"
#include "verification/exact_deviation.hpp"
#include "bench/bench_main.hpp"

namespace {

using namespace hybridctl;

int g_top_k = 0;  // plans per part: 0 as `plan` (its default); 1 for --smoke

void exact_against_voxels(benchmark::State& state, const std::string& part, const std::string& machine_file,
                          double tolerance = 0) {
  const std::string root = HYBRIDCTL_SOURCE_DIR "/";
  const config::Machine machine = config::load_machine(root + machine_file);
  const geometry::TriangleMesh mesh = geometry::read_stl(root + part);
  planner::PlanningOptions options;
  if (g_top_k > 0) options.top_k = g_top_k;
  if (tolerance > 0) options.tolerance = tolerance;
  const planner::PlanningResult planned = planner::plan_part(mesh, part, machine, options);
  const plan::PlanFile file = planner::to_plan_file(planned, {part, machine_file, machine.name, ""}, ".");
  if (file.plans.empty()) {
    state.SkipWithError((part + " has no plan on " + machine_file).c_str());
    return;
  }
  double voxels = 0, exact = 0;
  for (auto _ : state) {
    for (const plan::PlanFilePlan& p : file.plans) {
      validation::ExecutionOptions alone;
      alone.verify_exactly = false;
      voxels += bench::seconds_of([&] { benchmark::DoNotOptimize(validation::execute_plan(file, p, machine, alone)); });
      validation::ExecutionOptions with;
      with.surfaces = std::make_shared<verification::DesignSurfaces>(mesh, part);
      exact += bench::seconds_of([&] { benchmark::DoNotOptimize(validation::execute_plan(file, p, machine, with)); });
    }
  }
  const double plans = double(file.plans.size()) * double(state.iterations());
  state.counters["plans"] = double(file.plans.size());
  state.counters["voxels_s_per_plan"] = voxels / plans;
  state.counters["exact_s_per_plan"] = exact / plans;
  state.counters["added_ratio"] = voxels > 0 ? (exact - voxels) / voxels : 0;
}

BENCHMARK_CAPTURE(exact_against_voxels, flanged_hub, "examples/parts/flanged-hub.stl",
                  "examples/machines/hybrid-3axis.yaml")
    ->Iterations(1)
    ->Unit(benchmark::kSecond);
// A drawing's tolerance finer than the sampling's floor: the surface sampled 0.1 mm apart
// (verification::sampling_for), 25 times as many vectors as at the voxel's tolerance.
BENCHMARK_CAPTURE(exact_against_voxels, flanged_hub_at_4_microns, "examples/parts/flanged-hub.stl",
                  "examples/machines/hybrid-3axis.yaml", 0.004)
    ->Iterations(1)
    ->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(exact_against_voxels, tube_plate, "examples/parts/tube-plate.stl",
                  "examples/machines/multitask-b-axis.yaml")
    ->Iterations(1)
    ->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(exact_against_voxels, boss_plate, "examples/parts/boss-plate.stl",
                  "examples/machines/wire-ded-ti.yaml")
    ->Iterations(1)
    ->Unit(benchmark::kSecond);

// --smoke: the flanged hub's best plan, both ways, once.
void register_smoke_cases() {
  g_top_k = 1;
  hybridctl::bench::smoke_case("exact_against_voxels/flanged_hub", [](benchmark::State& state) {
    exact_against_voxels(state, "examples/parts/flanged-hub.stl", "examples/machines/hybrid-3axis.yaml");
  })->Unit(benchmark::kSecond);
}

}  // namespace

int main(int argc, char** argv) { return hybridctl::bench::run_benchmarks(argc, argv, register_smoke_cases); }
