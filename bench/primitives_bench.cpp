// The machine's primitives at the scale of a real machine: multitask-b-axis.yaml (2 heads,
// 5 tools, 4 setups: 50 primitives) at 0.5 mm on the bracket and the overhang part.
//
//   BM_MachinePrimitives/part    machine_primitives as `plan` calls it (the fast path)
//   BM_ReferenceRemovals/part    the same removal regions one by one by their definitions
//                                (subtractive_maximal / subtractive_conservative), the
//                                baseline the fast path must equal voxel for voxel
//                                (counter mismatches: regions that differ)
//   BM_GridPhases/part/voxel     primitives, atoms and their measures at voxel/100 mm: all
//                                that planning allocates before the search, next to the
//                                estimate `plan` checks --memory-budget against
//
// Counters: primitives, stocks_additive_s (wall time before the first removal), atoms,
// peak_rss_MiB (the process's peak so far: run one benchmark per process for a clean
// figure, as bench/planning-peak-memory does), estimate_MiB.
// Part 0 is the bracket, 1 the overhang. A run of the reference takes about a minute.

#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <chrono>
#include <string>

#include "bench/bench_main.hpp"

#include "config/machine_loader.hpp"
#include "geometry/mesh.hpp"
#include "geometry/voxelize.hpp"
#include "planner/atoms/atoms.hpp"
#include "planner/primitives/machine_primitives.hpp"
#include "planner/pipeline/memory_estimate.hpp"
#include "planner/primitives/shapes.hpp"

namespace {

using namespace hybridctl;
using geometry::Solid;

struct Job {
  config::Machine machine;
  Solid design;
  geometry::IndexBox domain;
};

// The design and domain as plan_part makes them (planner/pipeline/planning.cpp, voxelize_design).
Job job_for(int part, double voxel = 0) {
  const std::string root = HYBRIDCTL_SOURCE_DIR;
  const std::string name = part == 0 ? "bracket.stl" : "overhang.stl";
  Job j{config::load_machine(root + "/examples/machines/multitask-b-axis.yaml"), {}, {}};
  const geometry::Lattice lattice{voxel > 0 ? voxel : j.machine.planning.voxel_size, {0, 0, 0}};
  const Solid design = geometry::voxelize(geometry::read_stl(root + "/examples/parts/" + name), lattice, name,
                                          geometry::VoxelizeMethod::ExactScan);
  j.domain = planner::planning_domain(j.machine, lattice, design.bounding_box_mm(), j.machine.planning.tolerance);
  j.design = intersect(design, Solid::filled(lattice, j.domain));
  return j;
}

double peak_rss_mib() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_maxrss) / 1024.0;
}

void BM_MachinePrimitives(benchmark::State& state) {
  const Job j = job_for(int(state.range(0)));
  std::size_t count = 0;
  double additive_s = 0;
  for (auto _ : state) {
    // The stocks and additive primitives come first, then the removals in one batch.
    const auto start = std::chrono::steady_clock::now();
    bool removals = false;
    count = planner::machine_primitives(j.machine, j.design, j.domain,
                                        [&](std::size_t, std::size_t, const std::string& what) {
                                          if (removals || what.rfind("SM-", 0) != 0) return;
                                          removals = true;
                                          additive_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
                                        })
                .size();
  }
  state.counters["primitives"] = double(count);
  state.counters["stocks_additive_s"] = additive_s;
  state.counters["peak_rss_MiB"] = peak_rss_mib();
}

void BM_ReferenceRemovals(benchmark::State& state) {
  const Job j = job_for(int(state.range(0)));
  // The fast path's removal regions, in machine_primitives' order, to compare against.
  std::vector<Solid> fast;
  for (auto& p : planner::machine_primitives(j.machine, j.design, j.domain))
    if (p.mode == config::Mode::Subtractive) fast.push_back(std::move(p.region));
  std::size_t count = 0, mismatches = 0;
  for (auto _ : state) {
    count = mismatches = 0;
    for (const auto& tool : j.machine.tools)
      for (const auto& setup : j.machine.setups) {
        const planner::Instrument in = planner::tool_instrument(tool, setup.approach);
        for (const auto kind : tool.primitives) {
          const Solid s = kind == config::PrimitiveKind::SmMax ? planner::subtractive_maximal(j.design, in, j.domain)
                                                               : planner::subtractive_conservative(j.design, in, j.domain);
          if (count >= fast.size() || !(s == fast[count])) ++mismatches;
          ++count;
        }
      }
  }
  state.counters["primitives"] = double(count);
  state.counters["mismatches"] = double(mismatches);
  state.counters["peak_rss_MiB"] = peak_rss_mib();
}

// Everything plan_part allocates before the search, at a voxel size of range(1) / 100 mm:
// primitives, atoms, the tolerance zone and the atoms' measures; next to the estimate
// `plan` checks against --memory-budget (planner/pipeline/memory_estimate.hpp).
void BM_GridPhases(benchmark::State& state) {
  const double voxel = double(state.range(1)) / 100.0;
  const Job j = job_for(int(state.range(0)), voxel);
  int atoms = 0;
  for (auto _ : state) {
    const auto primitives = planner::machine_primitives(j.machine, j.design, j.domain);
    planner::AtomDecomposition d(j.design.lattice(), j.domain);
    for (const auto& p : primitives) d.add_primitive(p.region);
    const auto measures = planner::measure_atoms(d, j.design, planner::make_tolerance_zone(j.design, j.machine.planning.tolerance),
                                                 j.machine.planning.sliver_threshold);
    atoms = int(measures.size());
  }
  const auto part = j.design.bounding_box_mm();
  const planner::PlanningMemory estimate = planner::planning_memory(part, j.machine, voxel, j.machine.planning.tolerance);
  state.counters["atoms"] = atoms;
  state.counters["peak_rss_MiB"] = peak_rss_mib();
  state.counters["estimate_MiB"] = estimate.total() / (1024.0 * 1024.0);
}

BENCHMARK(BM_MachinePrimitives)->Arg(0)->Arg(1)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);
BENCHMARK(BM_ReferenceRemovals)->Arg(0)->Arg(1)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);
BENCHMARK(BM_GridPhases)->ArgsProduct({{0, 1}, {50, 25}})->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);

// --smoke: the grid phases of the bracket at 1 mm (the fast path and the reference have
// no smaller case than 0.5 mm: job_for's voxel size is theirs).
void register_smoke_cases() {
  hybridctl::bench::smoke_case("BM_GridPhases", BM_GridPhases)->Args({0, 100})->Unit(benchmark::kSecond);
}

}  // namespace

int main(int argc, char** argv) { return hybridctl::bench::run_benchmarks(argc, argv, register_smoke_cases); }
