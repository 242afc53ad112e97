// Inside corners no cutter reaches, against closed forms and the bladed disc: a tool along
// Z leaves an inside corner of angle a its radius times (1 / sin(a / 2) - 1); a flat end
// mill along X puts its square end into a right-angled corner it looks along, unless its
// shank, wider than its flutes, meets a wall beyond them; one that looks across a corner
// it cannot turn into stays off it; heights near a face that is not vertical are not named.

#include "toolpaths/corner_reach.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "config/machine_loader.hpp"
#include "geometry/mesh.hpp"
#include "test_meshes.hpp"

namespace hybridctl::toolpaths {
namespace {

using plan::UnreachedCorner;

// The B-axis machine with only the setups of `approaches` and only its 4 mm flat cutter
// (6 mm shank, 10 mm flutes).
config::Machine four_millimetre_cutter(const std::vector<config::Approach>& approaches) {
  config::Machine m = config::load_machine(HYBRIDCTL_SOURCE_DIR "/examples/machines/multitask-b-axis.yaml");
  std::vector<config::CuttingTool> tools;
  for (const config::CuttingTool& t : m.tools)
    if (t.number == 4) tools.push_back(t);
  m.tools = tools;
  std::vector<config::Setup> setups;
  for (const config::Approach a : approaches)
    for (const config::Setup& s : m.setups)
      if (s.approach == a) setups.push_back(s);
  m.setups = setups;
  return m;
}

// An L, 20 mm tall: the inside corner at (8, 8), its leg along X out to `leg_end`.
Mesh ell(double leg_end) { return prism({{0, 0}, {leg_end, 0}, {leg_end, 8}, {8, 8}, {8, 20}, {0, 20}}, 0, 20); }

CornerReachOptions at_tolerance(double reach) {
  CornerReachOptions o;
  o.reach = reach;
  return o;
}

TEST(CornerReach, ACutterAlongZLeavesARightAngledCornerItsRadiusTimesRootTwoLessOne) {
  const auto corners = corners_no_cutter_reaches(ell(16), four_millimetre_cutter({config::Approach::PlusZ}),
                                                 at_tolerance(0.3));
  ASSERT_EQ(corners.size(), 1u);
  const UnreachedCorner& c = corners.front();
  EXPECT_NEAR(c.from.x, 8, 1e-6);
  EXPECT_NEAR(c.from.y, 8, 1e-6);
  EXPECT_NEAR(c.air_angle, 90, 1e-3);
  // The disc of 2 mm stands off both walls by the allowance (0.005 mm) at least.
  EXPECT_NEAR(c.nearest, (2 - 0.005) * std::sqrt(2.0) - 2, 0.003) << c.nearest_by;
  EXPECT_NE(c.nearest_by.find("T4"), std::string::npos) << c.nearest_by;
  // Judged from the floor up to the reach below the top: a flat end's tip above the corner
  // must find the same walls within the reach.
  EXPECT_LT(c.from.z, 0.2);
  EXPECT_GT(c.to.z, 19.4);
  EXPECT_LE(c.to.z, 20 - 0.3 + 1e-9);
}

TEST(CornerReach, AFlatEndMillAlongXPutsItsSquareEndIntoTheCornerItLooksAlong) {
  // The leg along X is shorter than the flutes: nothing stands in the shank's way.
  EXPECT_TRUE(corners_no_cutter_reaches(ell(16), four_millimetre_cutter({config::Approach::PlusX}), at_tolerance(0.3))
                  .empty());
}

TEST(CornerReach, AShankWiderThanTheFlutesKeepsTheCutterOffACornerWhoseWallRunsPastThem) {
  // Along a 30 mm leg the 6 mm shank meets the wall 10 mm out: the cutter's side stands
  // 1 mm off it, less the allowance, where the walls stand a tool's radius above and below;
  // nearer the floor and the top the bound takes the shank's section off its axis.
  const auto corners =
      corners_no_cutter_reaches(ell(30), four_millimetre_cutter({config::Approach::PlusX}), at_tolerance(0.3));
  ASSERT_EQ(corners.size(), 1u);
  EXPECT_GT(corners.front().nearest, 0.3) << corners.front().nearest_by;
  EXPECT_LE(corners.front().nearest, 1 - 0.005 + 1e-3) << corners.front().nearest_by;
  EXPECT_LT(corners.front().from.z, 1.0);
  EXPECT_GT(corners.front().to.z, 19.0);
}

TEST(CornerReach, ACutterAlongYLooksAcrossACornerOfSixtyDegreesAndStaysOffIt) {
  // A wedge of air of 60 degrees between a wall along X and one leaning back at 60: along +Y
  // the square end meets the leaning wall before it gets into the corner.
  const double t = std::tan(std::numbers::pi / 3);
  const Mesh part = prism({{0, 0}, {30, 0}, {30, 4}, {4 / t + 10, 4}, {10 + 20 / t, 20}, {0, 20}}, 0, 20);
  const auto corners =
      corners_no_cutter_reaches(part, four_millimetre_cutter({config::Approach::PlusY}), at_tolerance(0.3));
  ASSERT_EQ(corners.size(), 1u);
  EXPECT_NEAR(corners.front().air_angle, 60, 1e-3);
  EXPECT_GT(corners.front().nearest, 0.3);
}

// The disc's six blades meet the hub in twelve inside corners of 93.7 degrees. Along X the
// 10 mm bull nose slides along the blades at 0 and 180 degrees into their corners (nothing
// wider than it for 70 mm); the blades at 60, 120, 240 and 300 degrees lie across every
// direction the machine has, and the 8 mm ball from above comes no nearer than 0.36 mm.
// Only heights a tool's span away from the base's top (z = 2) and the blades' tops
// (z = 12) are judged, where the walls are the same all round.
TEST(CornerReach, TheBladedDiscsBladesOffTheAxesMeetTheHubInCornersNoCutterOfTheBAxisMachineReaches) {
  const geometry::TriangleMesh disc = geometry::read_stl(HYBRIDCTL_SOURCE_DIR "/examples/parts/bladed-disc.stl");
  const config::Machine machine = config::load_machine(HYBRIDCTL_SOURCE_DIR "/examples/machines/multitask-b-axis.yaml");
  const auto corners = corners_no_cutter_reaches(geometry::clean_mesh(disc).triangles, machine, at_tolerance(0.3));
  ASSERT_EQ(corners.size(), 8u);
  for (const UnreachedCorner& c : corners) {
    // On the hub, beside a blade off the axes.
    const double dx = c.from.x - 30, dy = c.from.y - 30;
    EXPECT_NEAR(std::hypot(dx, dy), 10, 0.01);
    const double blade = std::fmod(std::atan2(dy, dx) * 180 / std::numbers::pi + 360 + 30, 60) - 30;
    EXPECT_NEAR(std::abs(blade), 7.18, 0.05) << c.from.x << ", " << c.from.y;
    EXPECT_GT(std::abs(std::atan2(dy, dx) * 180 / std::numbers::pi), 20);
    EXPECT_LT(std::abs(std::atan2(dy, dx) * 180 / std::numbers::pi), 160);
    EXPECT_NEAR(c.air_angle, 93.7, 0.1);
    EXPECT_GT(c.nearest, 0.3) << c.nearest_by;
    EXPECT_GE(c.from.z, 2.3);
    EXPECT_LE(c.to.z, 11.7);
    EXPECT_GT(c.to.z - c.from.z, 5.0);
  }
}

// A refusal needs one corner: a part with many is tried only until the cap is named.
TEST(CornerReach, CornersAreTriedOnlyUntilAsManyAsAskedAreNamed) {
  const geometry::TriangleMesh disc = geometry::read_stl(HYBRIDCTL_SOURCE_DIR "/examples/parts/bladed-disc.stl");
  const config::Machine machine = config::load_machine(HYBRIDCTL_SOURCE_DIR "/examples/machines/multitask-b-axis.yaml");
  CornerReachOptions o = at_tolerance(0.3);
  o.max_corners = 2;
  EXPECT_EQ(corners_no_cutter_reaches(geometry::clean_mesh(disc).triangles, machine, o).size(), 2u);
}

}  // namespace
}  // namespace hybridctl::toolpaths
