// What the proof that no cutter reaches an inside corner costs (docs/toolpaths.md, "Inside
// corners no cutter reaches"; docs/search.md, "Before the search: inside corners no
// instrument makes"): per part, corners_no_cutter_reaches against every tool and setup of
// the machine at its own tolerance, and in the same process a baseline of the same kind of
// work that finishing does anyway: the keep-out region of the machine's narrowest flat
// end mill from above (toolpaths::tip_keep_out) at the same heights. Counters: corners
// named, seconds, and the ratio to the baseline.
//
//   BUILD_TARGET=corner_reach_bench scripts/build -DHYBRIDCTL_BUILD_BENCH=ON
//   build/bench/corner_reach_bench
//   build/bench/corner_reach_bench --smoke   (the thin-wall slot block)
#include <benchmark/benchmark.h>

#include <algorithm>
#include <limits>
#include <string>

#include "bench/bench_main.hpp"
#include "config/machine_loader.hpp"
#include "geometry/mesh.hpp"
#include "toolpaths/corner_reach.hpp"
#include "toolpaths/wall_finish.hpp"

namespace {

using namespace hybridctl;

void corners(benchmark::State& state, const std::string& part, const std::string& machine_file) {
  const std::string root = HYBRIDCTL_SOURCE_DIR "/";
  const config::Machine machine = config::load_machine(root + machine_file);
  const std::vector<geometry::Triangle> design = geometry::clean_mesh(geometry::read_stl(root + part)).triangles;
  toolpaths::CornerReachOptions o;
  o.reach = machine.planning.tolerance;
  // The narrowest flat end mill, for the baseline.
  const config::CuttingTool* narrowest = nullptr;
  for (const config::CuttingTool& t : machine.tools)
    if (t.type == config::ToolType::Flat && (!narrowest || t.diameter < narrowest->diameter)) narrowest = &t;
  if (!narrowest) {
    state.SkipWithError((machine_file + " has no flat end mill for the baseline").c_str());
    return;
  }
  const std::vector<toolpaths::ToolBand> bands = toolpaths::flat_tool_bands(*narrowest);
  double zmin = std::numeric_limits<double>::infinity(), zmax = -zmin;
  for (const geometry::Triangle& t : design)
    for (const geometry::Vec3& v : t) zmin = std::min(zmin, v.z), zmax = std::max(zmax, v.z);
  double proof_s = 0, baseline_s = 0;
  std::size_t named = 0;
  for (auto _ : state) {
    proof_s += bench::seconds_of([&] { named = toolpaths::corners_no_cutter_reaches(design, machine, o).size(); });
    baseline_s += bench::seconds_of([&] {
      for (double z = zmin + o.step / 2; z < zmax; z += o.step)
        benchmark::DoNotOptimize(toolpaths::tip_keep_out(design, z, bands));
    });
  }
  const double runs = double(state.iterations());
  state.counters["corners"] = double(named);
  state.counters["proof_s"] = proof_s / runs;
  state.counters["keep_out_s"] = baseline_s / runs;
  state.counters["proof_to_keep_out"] = baseline_s > 0 ? proof_s / baseline_s : 0;
}

BENCHMARK_CAPTURE(corners, bladed_disc, "examples/parts/bladed-disc.stl", "examples/machines/multitask-b-axis.yaml")
    ->Iterations(1)
    ->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(corners, ribbed_pocket, "examples/parts/ribbed-pocket.stl", "examples/machines/multitask-b-axis.yaml")
    ->Iterations(1)
    ->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(corners, bracket, "examples/parts/bracket.stl", "examples/machines/multitask-b-axis.yaml")
    ->Iterations(1)
    ->Unit(benchmark::kSecond);

// --smoke: the thin-wall slot block, once.
void register_smoke_cases() {
  hybridctl::bench::smoke_case("corners/thin_wall_slot", [](benchmark::State& state) {
    corners(state, "examples/parts/thin-wall-slot.stl", "examples/machines/multitask-b-axis.yaml");
  })->Unit(benchmark::kSecond);
}

}  // namespace

int main(int argc, char** argv) { return hybridctl::bench::run_benchmarks(argc, argv, register_smoke_cases); }
