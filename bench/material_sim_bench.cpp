// Material simulation throughput, in moves per second (items_per_second):
//  - a 10 mm flat end mill (30 mm flute, 10 mm shank, 50 mm holder) making 20 mm moves
//    in a 200 x 200 x 50 mm stock at 0.5 mm voxels: level along X, level diagonal, and
//    ramps; at 10 mm depth and with the whole flute buried (40 mm depth);
//  - a 10 mm ball and a 10 mm bull-nose (2 mm corner) mill on ramps (the bull's corner
//    is decided voxel by voxel in a thin band on ramps);
//  - full circles of radius 20 mm (arcs as chords within a tenth of a voxel);
//  - 3 x 1.5 mm ellipsoid beads laid in 20 mm moves at 0.5 and 0.25 mm voxels.
// Moves walk a raster over the stock, so each meets fresh material and earlier cuts.

#include <benchmark/benchmark.h>

#include <cmath>

#include "bench/bench_main.hpp"

#include "sim/material.hpp"

namespace {

using namespace hybridctl;
using geometry::Vec3;

sim::Cutter mill(config::ToolType type, double corner = 0) {
  config::CuttingTool t;
  t.number = 1;
  t.type = type;
  t.diameter = 10;
  t.corner_radius = type == config::ToolType::Ball ? 5 : corner;
  t.flute_length = 30;
  t.shank = {10, 20};
  t.holder = {50, 60};
  return sim::cutter_of(t);
}

geometry::Solid stock_200x200x50(double h) {
  const geometry::Lattice l{h, {0, 0, 0}};
  return geometry::Solid::filled(l, {{0, 0, 0}, {int(200 / h), int(200 / h), int(50 / h)}});
}

// The i-th move of a raster: rows 12 mm apart, 20 mm moves in direction (dx, dy).
sim::MaterialMove raster_move(std::int64_t i, double z0, double dx, double dy, double dz, sim::Motion motion) {
  const int per_row = 8, rows = 15;
  const double x = 10 + 20 * double(i % per_row), y = 10 + 12 * double((i / per_row) % rows);
  return {motion, {x, y, z0}, {x + dx, y + dy, z0 + dz}, {}, true, int(i)};
}

void cut_moves(benchmark::State& state, sim::Cutter cutter, double depth, double dx, double dy, double dz) {
  sim::MaterialSimulation s(stock_200x200x50(0.5));
  std::int64_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(s.cut(cutter, raster_move(i++, 50 - depth, dx, dy, dz, sim::Motion::Linear)));
  }
  state.SetItemsProcessed(i);
  state.counters["removed_mm3"] = s.report().removed;
}

void BM_FlatLevelX(benchmark::State& st) { cut_moves(st, mill(config::ToolType::Flat), double(st.range(0)), 20, 0, 0); }
void BM_FlatLevelDiagonal(benchmark::State& st) {
  cut_moves(st, mill(config::ToolType::Flat), double(st.range(0)), 20 * std::sqrt(0.5), 20 * std::sqrt(0.5), 0);
}
void BM_FlatRamp(benchmark::State& st) { cut_moves(st, mill(config::ToolType::Flat), double(st.range(0)), 20, 0, -2); }
void BM_BallRamp(benchmark::State& st) { cut_moves(st, mill(config::ToolType::Ball), double(st.range(0)), 20, 0, -2); }
void BM_BullLevel(benchmark::State& st) { cut_moves(st, mill(config::ToolType::Bull, 2), double(st.range(0)), 20, 0, 0); }
void BM_BullRamp(benchmark::State& st) { cut_moves(st, mill(config::ToolType::Bull, 2), double(st.range(0)), 20, 0, -2); }
BENCHMARK(BM_FlatLevelX)->Arg(10)->Arg(40);
BENCHMARK(BM_FlatLevelDiagonal)->Arg(10)->Arg(40);
BENCHMARK(BM_FlatRamp)->Arg(10)->Arg(40);
BENCHMARK(BM_BallRamp)->Arg(10);
BENCHMARK(BM_BullLevel)->Arg(10);
BENCHMARK(BM_BullRamp)->Arg(10);

void BM_FlatFullCircle(benchmark::State& state) {
  const sim::Cutter cutter = mill(config::ToolType::Flat);
  sim::MaterialSimulation s(stock_200x200x50(0.5));
  std::int64_t i = 0;
  for (auto _ : state) {
    const Vec3 c{50 + 100 * double(i % 2), 50 + 100 * double((i / 2) % 2), 0};
    const Vec3 p{c.x + 20, c.y, 40};
    benchmark::DoNotOptimize(s.cut(cutter, {sim::Motion::ArcCcw, p, p, c, false, int(i)}));
    ++i;
  }
  state.SetItemsProcessed(i);
}
BENCHMARK(BM_FlatFullCircle);

void BM_BeadMoves(benchmark::State& state) {
  const double h = state.range(0) / 100.0;
  const sim::Bead bead{config::BeadShape::Ellipsoid, 3, 1.5, {}, {}};  // no nozzle body, no overhang
  const geometry::Lattice l{h, {0, 0, 0}};
  sim::MaterialSimulation s(geometry::Solid(l, {{0, 0, 0}, {int(200 / h), int(200 / h), int(50 / h)}}));
  std::int64_t i = 0;
  for (auto _ : state) {
    // Layers of a raster 2.1 mm apart, 1.2 mm per layer.
    const std::int64_t per_layer = 8 * 80;
    const double x = 10 + 20 * double(i % 8), y = 10 + 2.1 * double((i / 8) % 80), z = 1.2 * double(i / per_layer % 30);
    benchmark::DoNotOptimize(s.deposit(bead, {sim::Motion::Linear, {x, y, z}, {x + 20, y, z}, {}, true, int(i)}));
    ++i;
  }
  state.SetItemsProcessed(i);
  state.counters["deposited_mm3"] = s.report().deposited;
}
BENCHMARK(BM_BeadMoves)->Arg(50)->Arg(25);

// --smoke: one move of each kind at 10 mm depth, one bead at 0.5 mm.
void register_smoke_cases() {
  for (auto [name, fn] : {hybridctl::bench::NamedCase{"BM_FlatLevelX", BM_FlatLevelX}, hybridctl::bench::NamedCase{"BM_FlatLevelDiagonal", BM_FlatLevelDiagonal},
                          hybridctl::bench::NamedCase{"BM_FlatRamp", BM_FlatRamp}, hybridctl::bench::NamedCase{"BM_BallRamp", BM_BallRamp},
                          hybridctl::bench::NamedCase{"BM_BullLevel", BM_BullLevel}, hybridctl::bench::NamedCase{"BM_BullRamp", BM_BullRamp}})
    hybridctl::bench::smoke_case(name, fn)->Arg(10);
  hybridctl::bench::smoke_case("BM_FlatFullCircle", BM_FlatFullCircle);
  hybridctl::bench::smoke_case("BM_BeadMoves", BM_BeadMoves)->Arg(50);
}

}  // namespace

int main(int argc, char** argv) { return hybridctl::bench::run_benchmarks(argc, argv, register_smoke_cases); }
