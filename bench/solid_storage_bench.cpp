// Why Solid stores dense bits: the operations the planner repeats (boolean
// combination, counting, point queries) timed on the bracket at 0.25 mm in our layout
// and in an OpenVDB bool tree holding the same voxels.

#include <benchmark/benchmark.h>

#include <openvdb/openvdb.h>

#include <random>

#include "bench/bench_main.hpp"

#include "geometry/openvdb_bridge.hpp"
#include "geometry/shapes.hpp"
#include "geometry/voxelize.hpp"

namespace {

using namespace hybridctl::geometry;

struct Operands {
  Solid part, tool;
  openvdb::BoolGrid::Ptr part_grid, tool_grid;
  std::vector<Index3> probes;
};

const Operands& operands() {
  static const Operands o = [] {
    Operands o;
    const Lattice lattice{0.25, {0, 0, 0}};
    o.part = voxelize(read_stl(std::string(HYBRIDCTL_SOURCE_DIR) + "/examples/parts/bracket.stl"), lattice, "bracket");
    const Box3 b = o.part.bounding_box_mm();
    o.tool = make_sphere(lattice, {(b.min.x + b.max.x) / 2, (b.min.y + b.max.y) / 2, b.min.z}, 30);
    o.part_grid = vdb::to_bool_grid(o.part);
    o.tool_grid = vdb::to_bool_grid(o.tool);
    std::mt19937 rng(1);
    const IndexBox box = o.part.bounding_box();
    for (int i = 0; i < 1 << 16; ++i)
      o.probes.push_back({box.lo.x + int(rng() % unsigned(box.hi.x - box.lo.x)), box.lo.y + int(rng() % unsigned(box.hi.y - box.lo.y)),
                          box.lo.z + int(rng() % unsigned(box.hi.z - box.lo.z))});
    return o;
  }();
  return o;
}

void BM_Dense_Intersect(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(intersect(operands().part, operands().tool).voxel_count());
}
void BM_OpenVdb_Intersect(benchmark::State& state) {
  for (auto _ : state) {
    auto copy = operands().part_grid->deepCopy();
    copy->tree().topologyIntersection(operands().tool_grid->tree());
    benchmark::DoNotOptimize(copy->activeVoxelCount());
  }
}
void BM_Dense_Union(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(unite(operands().part, operands().tool).voxel_count());
}
void BM_OpenVdb_Union(benchmark::State& state) {
  for (auto _ : state) {
    auto copy = operands().part_grid->deepCopy();
    copy->tree().topologyUnion(operands().tool_grid->tree());
    benchmark::DoNotOptimize(copy->activeVoxelCount());
  }
}
void BM_Dense_PointQueries(benchmark::State& state) {
  for (auto _ : state) {
    int hits = 0;
    for (const Index3& p : operands().probes) hits += operands().part.contains(p);
    benchmark::DoNotOptimize(hits);
  }
  state.SetItemsProcessed(std::int64_t(state.iterations()) * std::int64_t(operands().probes.size()));
}
void BM_OpenVdb_PointQueries(benchmark::State& state) {
  for (auto _ : state) {
    auto accessor = operands().part_grid->getConstAccessor();
    int hits = 0;
    for (const Index3& p : operands().probes) hits += accessor.isValueOn(openvdb::Coord(p.x, p.y, p.z));
    benchmark::DoNotOptimize(hits);
  }
  state.SetItemsProcessed(std::int64_t(state.iterations()) * std::int64_t(operands().probes.size()));
}
void BM_Memory(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(operands().part.voxel_count());
  state.counters["dense_bytes"] = double(operands().part.storage_box().voxel_count()) / 8;
  state.counters["openvdb_bytes"] = double(operands().part_grid->memUsage());
  state.counters["occupied"] = double(operands().part.voxel_count());
}

BENCHMARK(BM_Dense_Intersect)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_OpenVdb_Intersect)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Dense_Union)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_OpenVdb_Union)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Dense_PointQueries)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_OpenVdb_PointQueries)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Memory)->Iterations(1);

// --smoke: every operation once, on the same operands (the bracket at 0.25 mm).
void register_smoke_cases() {
  for (auto [name, fn] : {hybridctl::bench::NamedCase{"BM_Dense_Intersect", BM_Dense_Intersect}, hybridctl::bench::NamedCase{"BM_OpenVdb_Intersect", BM_OpenVdb_Intersect},
                          hybridctl::bench::NamedCase{"BM_Dense_Union", BM_Dense_Union}, hybridctl::bench::NamedCase{"BM_OpenVdb_Union", BM_OpenVdb_Union},
                          hybridctl::bench::NamedCase{"BM_Dense_PointQueries", BM_Dense_PointQueries},
                          hybridctl::bench::NamedCase{"BM_OpenVdb_PointQueries", BM_OpenVdb_PointQueries}, hybridctl::bench::NamedCase{"BM_Memory", BM_Memory}})
    hybridctl::bench::smoke_case(name, fn)->Unit(benchmark::kMicrosecond);
}

}  // namespace

int main(int argc, char** argv) { return hybridctl::bench::run_benchmarks(argc, argv, register_smoke_cases); }
