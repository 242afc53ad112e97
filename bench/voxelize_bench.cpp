// Voxelizing the bundled bracket at 0.5, 0.25 and 0.125 mm, by exact scan conversion
// and, as the baseline in the same process, by OpenVDB's mesh-to-level-set. Report the
// ratio between the two rather than raw seconds: these machines are noisy.

#include <benchmark/benchmark.h>

#include "bench/bench_main.hpp"

#include "geometry/voxelize.hpp"

namespace {

using namespace hybridctl::geometry;

const TriangleMesh& bracket() {
  static const TriangleMesh mesh = clean_mesh(read_stl(std::string(HYBRIDCTL_SOURCE_DIR) + "/examples/parts/bracket.stl"));
  return mesh;
}

void voxelize_bracket(benchmark::State& state, VoxelizeMethod method) {
  const double voxel = 0.5 / double(state.range(0));  // range: 1, 2, 4 -> 0.5, 0.25, 0.125 mm
  const Lattice lattice{voxel, {0, 0, 0}};
  std::int64_t voxels = 0;
  for (auto _ : state) {
    const Solid s = method == VoxelizeMethod::ExactScan ? voxelize_exact_scan(bracket(), lattice)
                                                        : voxelize_openvdb(bracket(), lattice);
    voxels = s.voxel_count();
    benchmark::DoNotOptimize(voxels);
  }
  state.counters["voxel_mm"] = voxel;
  state.counters["occupied"] = double(voxels);
  state.counters["voxels_per_s"] = benchmark::Counter(double(voxels), benchmark::Counter::kIsIterationInvariantRate);
}

void BM_ExactScan(benchmark::State& state) { voxelize_bracket(state, VoxelizeMethod::ExactScan); }
void BM_OpenVdbLevelSet(benchmark::State& state) { voxelize_bracket(state, VoxelizeMethod::OpenVdbLevelSet); }

BENCHMARK(BM_ExactScan)->Arg(1)->Arg(2)->Arg(4)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_OpenVdbLevelSet)->Arg(1)->Arg(2)->Arg(4)->Unit(benchmark::kMillisecond)->UseRealTime();

// --smoke: both methods at 0.5 mm, once.
void register_smoke_cases() {
  hybridctl::bench::smoke_case("BM_ExactScan", BM_ExactScan)->Arg(1)->Unit(benchmark::kMillisecond);
  hybridctl::bench::smoke_case("BM_OpenVdbLevelSet", BM_OpenVdbLevelSet)->Arg(1)->Unit(benchmark::kMillisecond);
}

}  // namespace

int main(int argc, char** argv) { return hybridctl::bench::run_benchmarks(argc, argv, register_smoke_cases); }
