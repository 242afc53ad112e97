// The part a program makes against the design's real surface, on parts whose answer is
// known in closed form: a cylinder milled by a circular toolpath, the same toolpath
// 0.1 mm out, a face left 0.1 mm high that the voxels cannot see.
#include "verification/exact_deviation.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "config/machine_loader.hpp"
#include "geometry/shapes.hpp"
#include "plan/deviation.hpp"
#include "sim/executor.hpp"
#include "verification_meshes.hpp"

namespace hybridctl::verification {
namespace {

using geometry::Vec3;

const config::Machine& machine() {
  static const config::Machine m = config::load_machine("examples/machines/hybrid-3axis.yaml");
  return m;
}

gcode::PostedProgram program(std::vector<std::string> lines) {
  gcode::PostedProgram p;
  p.lines = std::move(lines);
  p.origins.resize(p.lines.size());
  return p;
}

// The 3 mm flat cutter (T3, r 1.5, 8 mm flute) once round a cylinder of r 10 about
// (25, 25), z 0..4, its path at radius `path`.
gcode::PostedProgram around_cylinder(double path) {
  const std::string x = std::to_string(25 + path), i = std::to_string(-path);
  return program({"G21 G90 G17 G54", "T3 M6", "S18000 M3", "G0 X" + x + " Y25 Z20", "G1 Z-1 F150",
                  "G2 X" + x + " Y25 I" + i + " J0 F600", "G0 Z20", "M5", "M2"});
}

geometry::Solid stock_box(Vec3 lo, Vec3 hi) {
  const geometry::Lattice lattice{0.5, {0, 0, 0}};
  return geometry::make_box(lattice, {lo, hi});
}

TEST(ExactDeviation, ACylinderMilledByACircleIsWithinFiveMicronsOfItsRadius) {
  const DesignSurface surface(testing::cylinder_mesh(25, 25, 10, 0, 4, 720), "cylinder", sampling_for(0.01, 0.5));
  const plan::ExactDeviation d =
      verify_program(surface, machine(), around_cylinder(11.5), stock_box({13, 13, 0}, {37, 37, 4}), {0.01});
  EXPECT_LT(d.excess.mm, 0.005);
  EXPECT_LT(d.gouge.mm, 0.005);
  EXPECT_TRUE(d.within_tolerance());
  EXPECT_DOUBLE_EQ(d.within_share, 1.0);
  EXPECT_GT(d.samples, 10000u);
}

TEST(ExactDeviation, TheSameCircleATenthOutLeavesATenthOfExcessRoundTheWall) {
  const DesignSurface surface(testing::cylinder_mesh(25, 25, 10, 0, 4, 720), "cylinder", sampling_for(0.05, 0.5));
  const plan::ExactDeviation d =
      verify_program(surface, machine(), around_cylinder(11.6), stock_box({13, 13, 0}, {37, 37, 4}), {0.05});
  EXPECT_NEAR(d.excess.mm, 0.1, 0.005);
  EXPECT_LT(d.gouge.mm, 0.005);
  EXPECT_FALSE(d.within_tolerance());
  ASSERT_TRUE(d.excess.at);
  EXPECT_NEAR(std::hypot(d.excess.at->x - 25, d.excess.at->y - 25), 10.1, 0.005);
  EXPECT_EQ(d.excess.line, 6);  // the circle
  // The top and bottom faces are right: the share within is the wall's complement.
  EXPECT_NEAR(d.within_share, 2 * 3.14159265 * 100 / (2 * 3.14159265 * 100 + 2 * 3.14159265 * 10 * 4), 0.02);
  EXPECT_NE(plan::exact_deviation_text(d).find("OUTSIDE"), std::string::npos);
}

TEST(ExactDeviation, AFaceLeftATenthHighIsCaughtWhereTheVoxelsSeeNothing) {
  // A 10 mm cube from a 12 mm tall stock, faced by the 10 mm flat cutter at z 10.1: the
  // voxel centres (at 9.75 and 10.25) come out exactly as the design's.
  const geometry::TriangleMesh cube = testing::box_mesh({20, 20, 0}, {30, 30, 10});
  const geometry::Solid stock = stock_box({20, 20, 0}, {30, 30, 12});
  const gcode::PostedProgram facing =
      program({"G21 G90 G17 G54", "T1 M6", "S8000 M3", "G0 X12 Y17 Z20", "G1 Z10.1 F300", "G1 X38 F1200", "G1 Y21",
               "G1 X12", "G1 Y25", "G1 X38", "G1 Y29", "G1 X12", "G1 Y33", "G1 X38", "G0 Z20", "M5", "M2"});

  sim::ExecutorOptions on_voxels;
  on_voxels.stock = stock;
  sim::ProgramExecutor executor(machine(), "facing", on_voxels);
  for (std::size_t k = 0; k < facing.lines.size(); ++k) executor.execute_line(facing.lines[k], int(k + 1));
  const geometry::Solid design = geometry::make_box(stock.lattice(), {{20, 20, 0}, {30, 30, 10}});
  EXPECT_TRUE(plan::measure_deviation(executor.stock(), design, stock.bounding_box(), 0.05).within_tolerance);

  const DesignSurface surface(cube, "cube", sampling_for(0.05, 0.5));
  const plan::ExactDeviation d = verify_program(surface, machine(), facing, stock, {0.05});
  EXPECT_NEAR(d.excess.mm, 0.1, 1e-9);
  EXPECT_FALSE(d.within_tolerance());
  ASSERT_TRUE(d.excess.at);
  EXPECT_NEAR(d.excess.at->z, 10.1, 1e-9);
  EXPECT_GE(d.excess.line, 5);  // a facing move
  EXPECT_LE(d.excess.line, 14);
  EXPECT_LT(d.gouge.mm, 1e-9);
}

TEST(ExactDeviation, AFaceLeftAsDepositedCarriesItsHeadsAccuracy) {
  // A strip of beads laid by the powder head (accuracy 0.25 mm) as the whole part: its
  // top is the bead's, so both figures grow by the head's accuracy.
  const config::Machine& m = machine();
  const geometry::TriangleMesh slab = testing::box_mesh({20, 20, 0}, {24, 21, 0.75});
  const geometry::Solid empty(geometry::Lattice{0.5, {0, 0, 0}}, {{0, 0, 0}, {100, 100, 20}});
  const gcode::PostedProgram bead = program({"G21 G90 G17 G54", "T100 M6", "G0 X20 Y20.5 Z0", "M64 P0",
                                             "G1 X24 F800", "M65 P0", "G0 Z20", "M2"});
  const DesignSurface surface(slab, "slab", sampling_for(0.5, 0.5));
  const plan::ExactDeviation d = verify_program(surface, m, bead, empty, {0.5});
  EXPECT_TRUE(d.excess.as_deposited || d.gouge.as_deposited);
  EXPECT_GE(std::max(d.excess.mm, d.gouge.mm), m.heads[0].accuracy);
}

TEST(ExactDeviation, ABeadThatOnlyTouchesAVectorsEndLeavesNothingACutMustTakeAway) {
  // A bead laid on top of a 10 mm cube with its underside at z 12, exactly where the top
  // face's vectors end (2 mm out at this tolerance), then the top faced at z 10. The bead
  // meets those vectors in a single point: no material. It used to stay on them as a run of
  // no length that no cut could take away (a cut's span ends there too), and the faced top
  // came out "at least 2 mm" high, as on the boss plate's plate face round its deposited boss.
  const geometry::TriangleMesh cube = testing::box_mesh({20, 20, 0}, {30, 30, 10});
  const geometry::Solid stock = stock_box({20, 20, 0}, {30, 30, 10});
  const gcode::PostedProgram laid_then_faced =
      program({"G21 G90 G17 G54", "T100 M6", "G0 X21 Y25 Z12", "M64 P0", "G1 X29 F800", "M65 P0", "G0 Z20", "T1 M6",
               "S8000 M3", "G0 X12 Y17 Z20", "G1 Z10 F300", "G1 X38 F1200", "G1 Y21", "G1 X12", "G1 Y25", "G1 X38",
               "G1 Y29", "G1 X12", "G1 Y33", "G1 X38", "G0 Z20", "M5", "M2"});
  const DesignSurface surface(cube, "cube", sampling_for(0.5, 0.5));
  const plan::ExactDeviation d = verify_program(surface, machine(), laid_then_faced, stock, {0.5});
  EXPECT_LT(d.excess.mm, 1e-6);
  EXPECT_FALSE(d.excess.at_least);
  EXPECT_LT(d.gouge.mm, 1e-6);
  EXPECT_TRUE(d.within_tolerance());
}

}  // namespace
}  // namespace hybridctl::verification
