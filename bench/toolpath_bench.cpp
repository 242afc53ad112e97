// Toolpath generation on a region of about 100^3 voxels (0.5 mm voxels, a 50 mm cube):
//   - raster deposition of a block with a through hole on a base plate, with the bundled
//     machine's DED head (1.5 mm bead, 0.6 mm layers, 1.05 mm hatch), with and without
//     a contour pass;
//   - Z-level pocketing of a 50 x 50 x 50 mm pocket around a round boss with the bundled
//     10 mm flat rougher (5 mm step down, 4 mm step over, 42 mm holder), zigzag and
//     contour-parallel rings, and with the 3 mm flat detail tool (1 mm step down);
//   - the bundled bladed disc's hub and blades laid from its base disc by the DED head:
//     the voxel contour (arg 0) and near-net on the STL's exact sections (arg 1,
//     toolpaths/near_net_contour.hpp): their ratio is what the exact contour costs;
//   - the bundled rounded box with its dimple milled from a block over it by the B-axis
//     machine's 8 mm ball (0.4 mm step down), Z-levels alone (arg 0) and with surface
//     finishing on the STL at a 0.1 mm scallop (arg 1): their ratio is what finishing adds.
// Counters: moves, cutting/deposition path length (mm), ROI voxels.

#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>

#include "bench/bench_main.hpp"

#include "toolpaths/deposition_path.hpp"
#include "toolpaths/pocket_path.hpp"
#include "geometry/mesh.hpp"
#include "geometry/shapes.hpp"
#include "geometry/voxelize.hpp"

namespace {

using namespace hybridctl;
using geometry::Lattice;
using geometry::Solid;

const Lattice kLattice{0.5, {0, 0, 0}};

config::Setup top() {
  config::Setup s;
  s.name = "top";
  return s;
}

config::AdditiveHead ded() {
  config::AdditiveHead h;
  h.name = "ded";
  h.bead = {config::BeadShape::Ellipsoid, 1.5, 0.75};
  h.nozzle = config::Nozzle{20, 60};
  h.layer_height = 0.6;
  h.hatch_spacing = 1.05;
  h.travel_clearance = 5;
  h.feed = 800;
  return h;
}

config::CuttingTool rougher() {
  config::CuttingTool t;
  t.number = 1;
  t.name = "10 mm flat rougher";
  t.diameter = 10;
  t.flute_length = 22;
  t.shank = {10, 50};
  t.holder = {42, 60};
  t.feed = 1200;
  t.plunge_feed = 300;
  t.step_down = 5;
  t.step_over = 4;
  return t;
}

config::CuttingTool detail() {
  config::CuttingTool t;
  t.number = 3;
  t.name = "3 mm flat detail";
  t.diameter = 3;
  t.flute_length = 8;
  t.shank = {6, 30};
  t.holder = {35, 60};
  t.feed = 600;
  t.plunge_feed = 150;
  t.step_down = 1;
  t.step_over = 1.2;
  return t;
}

void count(benchmark::State& state, const gcode::Toolpath& p, const Solid& roi) {
  double length = 0;
  geometry::Vec3 at = p.start;
  for (const auto& m : p.moves) {
    if (m.process_on) length += std::hypot(m.to.x - at.x, m.to.y - at.y, m.to.z - at.z);
    at = m.to;
  }
  state.counters["moves"] = double(p.moves.size());
  state.counters["path_mm"] = length;
  state.counters["roi_voxels"] = double(roi.voxel_count());
  state.counters["warnings"] = double(p.warnings.size());
}

void BM_Deposition(benchmark::State& state) {
  const Solid base = geometry::make_box(kLattice, {{0, 0, 0}, {60, 60, 5}});
  Solid roi = geometry::make_box(kLattice, {{5, 5, 5}, {55, 55, 55}});
  roi = geometry::subtract(roi, geometry::make_cylinder(kLattice, geometry::Axis::Z, {30, 30, 0}, 8, 60));
  toolpaths::DepositionOptions o;
  if (state.range(0)) o.contour = toolpaths::ContourPass::BeforeInfill;
  gcode::Toolpath p;
  for (auto _ : state) {
    p = toolpaths::deposition_path(roi, base, ded(), top(), o);
    benchmark::DoNotOptimize(p.moves.data());
  }
  count(state, p, roi);
}

void BM_NearNetDisc(benchmark::State& state) {
  const auto mesh = std::make_shared<const std::vector<geometry::Triangle>>(
      geometry::read_stl(HYBRIDCTL_SOURCE_DIR "/examples/parts/bladed-disc.stl").triangles);
  const Solid design = geometry::voxelize(geometry::TriangleMesh{*mesh}, kLattice, "bladed disc");
  const Solid base = geometry::intersect(design, geometry::make_box(kLattice, {{-1, -1, -1}, {61, 61, 2}}));
  const Solid roi = geometry::subtract(design, base);
  toolpaths::DepositionOptions o;
  if (state.range(0)) {
    o.near_net_design = mesh;
    o.near_net_slack = 0.125;  // hybrid-3axis: (0.5 mm tolerance - 0.25 mm accuracy) / 2
  }
  gcode::Toolpath p;
  for (auto _ : state) {
    p = toolpaths::deposition_path(roi, base, ded(), top(), o);
    benchmark::DoNotOptimize(p.moves.data());
  }
  count(state, p, roi);
}

void pocket(benchmark::State& state, const config::CuttingTool& tool, toolpaths::PocketStrategy strategy) {
  const Solid stock = geometry::make_box(kLattice, {{0, 0, 0}, {60, 60, 55}});
  Solid roi = geometry::make_box(kLattice, {{5, 5, 5}, {55, 55, 55}});
  roi = geometry::subtract(roi, geometry::make_cylinder(kLattice, geometry::Axis::Z, {30, 30, 0}, 8, 60));
  const Solid keep = geometry::subtract(stock, roi);
  toolpaths::PocketOptions o;
  o.strategy = strategy;
  gcode::Toolpath p;
  for (auto _ : state) {
    p = toolpaths::pocket_path(roi, keep, stock, tool, top(), o);
    benchmark::DoNotOptimize(p.moves.data());
  }
  count(state, p, roi);
}

void BM_BallOnTheRoundedBox(benchmark::State& state) {
  const auto mesh = std::make_shared<const std::vector<geometry::Triangle>>(
      geometry::read_stl(HYBRIDCTL_SOURCE_DIR "/examples/parts/rounded-box-dimple.stl").triangles);
  const Solid design = geometry::voxelize(geometry::TriangleMesh{*mesh}, kLattice, "rounded box");
  const Solid stock = geometry::make_box(kLattice, {{0, 0, 0}, {50, 40, 22}});
  const Solid roi = geometry::subtract(stock, design);
  config::CuttingTool ball;
  ball.number = 3;
  ball.name = "8 mm ball finisher";
  ball.type = config::ToolType::Ball;
  ball.diameter = 8;
  ball.flute_length = 16;
  ball.shank = {8, 50};
  ball.holder = {50, 80};
  ball.feed = 1600;
  ball.plunge_feed = 400;
  ball.step_down = 0.4;
  ball.step_over = 0.5;
  toolpaths::PocketOptions o;
  o.design = mesh;
  o.design_voxels = &design;
  o.finish_surfaces = state.range(0) != 0;
  o.scallop = 0.1;
  gcode::Toolpath p;
  for (auto _ : state) {
    p = toolpaths::pocket_path(roi, design, stock, ball, top(), o);
    benchmark::DoNotOptimize(p.moves.data());
  }
  count(state, p, roi);
}

void BM_PocketZigzag_Rougher(benchmark::State& s) { pocket(s, rougher(), toolpaths::PocketStrategy::Zigzag); }
void BM_PocketOffsets_Rougher(benchmark::State& s) { pocket(s, rougher(), toolpaths::PocketStrategy::Offsets); }
void BM_PocketZigzag_Detail(benchmark::State& s) { pocket(s, detail(), toolpaths::PocketStrategy::Zigzag); }

// --smoke: each path once on the same region.
void register_smoke_cases() {
  hybridctl::bench::smoke_case("BM_Deposition", BM_Deposition)->Arg(0)->Unit(benchmark::kMillisecond);
  for (auto [name, fn] : {hybridctl::bench::NamedCase{"BM_PocketZigzag_Rougher", BM_PocketZigzag_Rougher},
                          hybridctl::bench::NamedCase{"BM_PocketOffsets_Rougher", BM_PocketOffsets_Rougher},
                          hybridctl::bench::NamedCase{"BM_PocketZigzag_Detail", BM_PocketZigzag_Detail}})
    hybridctl::bench::smoke_case(name, fn)->Unit(benchmark::kMillisecond);
  hybridctl::bench::smoke_case("BM_BallOnTheRoundedBox", BM_BallOnTheRoundedBox)->Arg(1)->Unit(benchmark::kMillisecond);
  hybridctl::bench::smoke_case("BM_NearNetDisc", BM_NearNetDisc)->Arg(1)->Unit(benchmark::kMillisecond);
}

}  // namespace

BENCHMARK(BM_Deposition)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_NearNetDisc)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_PocketZigzag_Rougher)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_PocketOffsets_Rougher)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_PocketZigzag_Detail)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_BallOnTheRoundedBox)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

int main(int argc, char** argv) { return hybridctl::bench::run_benchmarks(argc, argv, register_smoke_cases); }
