// What finishing on the STL costs (docs/toolpaths.md, "Wall finishing" and "Surface
// finishing"): each part is planned once by the search alone (timed: the rest of
// planning), then every plan's toolpaths are made twice in the same process, roughing
// alone (PocketOptions::finish_walls and finish_surfaces off) and with finishing, one after
// the other. Counters: seconds of finishing per part (all its plans), its ratio to the
// search's planning (aim: at most 1 at 0.5 mm voxels), and the cycle minutes finishing adds
// per plan under `gcode check`'s time model.
//
//   BUILD_TARGET=finishing_bench scripts/build -DHYBRIDCTL_BUILD_BENCH=ON
//   build/bench/finishing_bench
//   build/bench/finishing_bench --smoke   (the flanged hub's best plan at 1 mm)
#include <benchmark/benchmark.h>

#include <chrono>
#include <string>

#include "config/machine_loader.hpp"
#include "gcode/check.hpp"
#include "gcode/post.hpp"
#include "geometry/mesh.hpp"
#include "planner/pipeline/plan_report.hpp"
#include "planner/pipeline/planning.hpp"
#include "toolpaths/plan_export.hpp"
#include "bench/bench_main.hpp"

namespace {

using namespace hybridctl;

int g_top_k = 0;         // plans per part: 0 as `plan` (its default); 1 for --smoke
double g_voxel = 0.5;    // 1 for --smoke

// Minutes of motion and dwell of the plan's action programs under `gcode check`'s time
// model (the changes between them are the same with finishing and without).
double cycle_minutes(const toolpaths::PlanExport& made, const config::Machine& machine) {
  double minutes = 0;
  for (const toolpaths::ExportedAction& a : made.actions) {
    if (!a.makes_gcode) continue;
    const gcode::TimeEstimate t = gcode::check_program(gcode::write_action(a.program, machine), machine, a.primitive).time;
    minutes += (t.motion + t.dwell) / 60.0;
  }
  return minutes;
}

void finishing(benchmark::State& state, const std::string& part, const std::string& machine_file) {
  const std::string root = HYBRIDCTL_SOURCE_DIR "/";
  const config::Machine machine = config::load_machine(root + machine_file);
  const geometry::TriangleMesh mesh = geometry::read_stl(root + part);
  planner::PlanningOptions options;
  options.voxel_size = g_voxel;
  if (g_top_k > 0) options.top_k = g_top_k;
  planner::PlanningResult planned;
  const double planning = bench::seconds_of([&] { planned = planner::plan_part(mesh, part, machine, options); });
  const plan::PlanFile file = planner::to_plan_file(planned, {part, machine_file, machine.name, ""}, ".");
  if (file.plans.empty()) {
    state.SkipWithError((part + " has no plan on " + machine_file).c_str());
    return;
  }
  toolpaths::ExportOptions rough, finished;
  rough.pocket.finish_walls = rough.pocket.finish_surfaces = false;
  double rough_s = 0, finished_s = 0, added_minutes = 0;
  for (auto _ : state) {
    for (const plan::PlanFilePlan& p : file.plans) {
      toolpaths::PlanExport a, b;
      rough_s += bench::seconds_of([&] { a = toolpaths::export_plan(file, p, machine, rough); });
      finished_s += bench::seconds_of([&] { b = toolpaths::export_plan(file, p, machine, finished); });
      added_minutes += cycle_minutes(b, machine) - cycle_minutes(a, machine);
    }
  }
  const double runs = double(state.iterations());
  const double finishing_s = (finished_s - rough_s) / runs;
  state.counters["plans"] = double(file.plans.size());
  state.counters["planning_s"] = planning;
  state.counters["roughing_s"] = rough_s / runs;
  state.counters["finishing_s"] = finishing_s;
  state.counters["finishing_to_planning"] = planning > 0 ? finishing_s / planning : 0;
  state.counters["cycle_min_added_per_plan"] = added_minutes / (runs * double(file.plans.size()));
}

BENCHMARK_CAPTURE(finishing, flanged_hub, "examples/parts/flanged-hub.stl", "examples/machines/hybrid-3axis.yaml")
    ->Iterations(1)
    ->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(finishing, tube_plate, "examples/parts/tube-plate.stl", "examples/machines/multitask-b-axis.yaml")
    ->Iterations(1)
    ->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(finishing, boss_plate, "examples/parts/boss-plate.stl", "examples/machines/wire-ded-ti.yaml")
    ->Iterations(1)
    ->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(finishing, rounded_box_dimple, "examples/parts/rounded-box-dimple.stl",
                  "examples/machines/multitask-b-axis.yaml")
    ->Iterations(1)
    ->Unit(benchmark::kSecond);

// --smoke: the flanged hub's best plan at 1 mm, both ways, once.
void register_smoke_cases() {
  g_top_k = 1;
  g_voxel = 1.0;
  hybridctl::bench::smoke_case("finishing/flanged_hub", [](benchmark::State& state) {
    finishing(state, "examples/parts/flanged-hub.stl", "examples/machines/hybrid-3axis.yaml");
  })->Unit(benchmark::kSecond);
}

}  // namespace

int main(int argc, char** argv) { return hybridctl::bench::run_benchmarks(argc, argv, register_smoke_cases); }
