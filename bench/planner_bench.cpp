// Planner benchmarks: atom decomposition at 256^3 with 8 and 32 primitives (incremental
// splitting against the full recompute), A* on synthetic instances with n = 8..24
// primitives (expanded states; against the exhaustive enumerator where it finishes), and
// `plan` end to end on the bracket at 0.5 and 0.25 mm.

#include <benchmark/benchmark.h>

#include <random>

#include "config/machine_loader.hpp"
#include "geometry/shapes.hpp"
#include "geometry/voxelize.hpp"
#include "planner/atoms.hpp"
#include "planner/planning.hpp"
#include "planner/search.hpp"

namespace {

using namespace hybridctl;
using geometry::IndexBox;
using geometry::Lattice;
using geometry::Solid;

const Lattice kUnit{1.0, {0, 0, 0}};

std::vector<Solid> random_primitives(int n, int grid, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> at(0, grid * 0.8), size(grid * 0.1, grid * 0.6);
  std::vector<Solid> out;
  for (int i = 0; i < n; ++i) {
    const double x = at(rng), y = at(rng), z = at(rng);
    if (i % 2) {
      out.push_back(geometry::make_sphere(kUnit, {x, y, z}, size(rng) / 2));
    } else {
      out.push_back(geometry::make_box(kUnit, {{x, y, z}, {x + size(rng), y + size(rng), z + size(rng)}}));
    }
  }
  return out;
}

void BM_DecomposeIncremental(benchmark::State& state) {
  const int n = int(state.range(0)), grid = 256;
  const auto prims = random_primitives(n, grid, 5);
  const IndexBox domain{{0, 0, 0}, {grid, grid, grid}};
  int atoms = 0;
  for (auto _ : state) {
    planner::AtomDecomposition d(kUnit, domain);
    for (const Solid& p : prims) d.add_primitive(p);
    atoms = d.atom_count();
  }
  state.counters["atoms"] = atoms;
}

void BM_DecomposeRecompute(benchmark::State& state) {
  const int n = int(state.range(0)), grid = 256;
  const auto prims = random_primitives(n, grid, 5);
  std::vector<const Solid*> pointers;
  for (const Solid& p : prims) pointers.push_back(&p);
  const IndexBox domain{{0, 0, 0}, {grid, grid, grid}};
  int atoms = 0;
  for (auto _ : state) atoms = planner::AtomDecomposition::recompute(kUnit, domain, pointers).atom_count();
  state.counters["atoms"] = atoms;
}

BENCHMARK(BM_DecomposeIncremental)->Arg(8)->Arg(32)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_DecomposeRecompute)->Arg(8)->Arg(32)->Unit(benchmark::kMillisecond)->UseRealTime();

// A synthetic symbolic instance: random atoms and primitives, the design the outcome of
// a random valid plan, so that plans exist.
planner::PlanningProblem synthetic_problem(int n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  const int atoms = 4 * n;
  planner::PlanningProblem p;
  std::uniform_real_distribution<double> volume(1, 100), cost(0.2, 3);
  p.atoms.resize(std::size_t(atoms));
  for (auto& a : p.atoms) a.volume = volume(rng);
  for (int i = 0; i < n; ++i) {
    planner::PrimitiveSpec s;
    s.name = "P" + std::to_string(i + 1);
    s.mode = i < 2 || rng() % 2 ? planner::Mode::Additive : planner::Mode::Subtractive;
    s.cost_per_mm3 = cost(rng);
    s.atoms = planner::AtomSet(atoms);
    for (int a = 0; a < atoms; ++a)
      if (rng() % 3 == 0) s.atoms.set(a);
    p.primitives.push_back(s);
  }
  planner::AtomSet state(atoms);
  std::vector<int> order(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) order[std::size_t(i)] = i;
  std::shuffle(order.begin() + 1, order.end(), rng);
  for (int k = 0; k < std::min(n, 6); ++k) {
    const auto& prim = p.primitives[std::size_t(order[std::size_t(k)])];
    for (int a = 0; a < atoms; ++a)
      if (prim.atoms.test(a)) state.set(a, prim.mode == planner::Mode::Additive);
  }
  for (int a = 0; a < atoms; ++a) {
    p.atoms[std::size_t(a)].must_in = state.test(a);
    p.atoms[std::size_t(a)].must_out = !state.test(a);
  }
  return p;
}

// Random instances vary a lot in difficulty: three seeds per size. The search stops at
// 2 million expansions (counter "limit" = 1 then) so the run always ends.
void BM_AStar(benchmark::State& state) {
  const auto p = synthetic_problem(int(state.range(0)), std::uint32_t(state.range(1)));
  planner::SearchStats stats;
  std::size_t found = 0;
  for (auto _ : state) found = planner::find_plans(p, {5, 2'000'000}, &stats).size();
  state.counters["expanded"] = double(stats.expanded);
  state.counters["plans"] = double(found);
  state.counters["limit"] = stats.limit_reached ? 1 : 0;
}

void BM_Exhaustive(benchmark::State& state) {
  const auto p = synthetic_problem(int(state.range(0)), std::uint32_t(state.range(1)));
  std::size_t found = 0;
  for (auto _ : state) found = planner::enumerate_plans(p, 5).size();
  state.counters["plans"] = double(found);
}

BENCHMARK(BM_AStar)->ArgsProduct({{8, 12, 16, 24}, {11, 12, 13}})->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Exhaustive)->ArgsProduct({{8}, {11, 12, 13}})->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_PlanBracket(benchmark::State& state) {
  const double voxel = state.range(0) == 1 ? 0.5 : 0.25;
  const auto machine = config::load_machine(std::string(HYBRIDCTL_SOURCE_DIR) + "/examples/machines/hybrid-3axis.yaml");
  const auto mesh = geometry::read_stl(std::string(HYBRIDCTL_SOURCE_DIR) + "/examples/parts/bracket.stl");
  planner::PlanningOptions options;
  options.voxel_size = voxel;
  std::size_t plans = 0;
  for (auto _ : state) plans = planner::plan_part(mesh, "bracket.stl", machine, options).plans.size();
  state.counters["voxel_mm"] = voxel;
  state.counters["plans"] = double(plans);
}

BENCHMARK(BM_PlanBracket)->Arg(1)->Arg(2)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
