// One tool, three users: from one flat, ball and bull tool, the planner's primitive
// instrument (planner::tool_instrument), the pocket generator's guard
// (instruments::conservative_guard of the whole tool) and the simulator's sweep body
// (sim::pieces_of the sim::cutter_of sections) are derived, and they agree: the same
// profile for planner and simulator (radii at sampled heights, and the same voxels), and
// a guard that holds the exact shape at every tip height up to one voxel above a level
// while being no wider than the exact shape within one voxel below it (elements.hpp).

#include "instruments/cutter.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <tuple>
#include <variant>

#include "geometry/morphology.hpp"
#include "instruments/elements.hpp"
#include "planner/primitives/machine_primitives.hpp"
#include "sim/instrument.hpp"
#include "sim/sweep.hpp"

namespace hybridctl::instruments {
namespace {

using geometry::AxialBody;
using geometry::AxialSection;
using geometry::Index3;

config::CuttingTool tool_of(config::ToolType type) {
  config::CuttingTool t;
  t.number = 7;
  t.type = type;
  t.diameter = 4;
  t.corner_radius = type == config::ToolType::Bull ? 0.75 : 0;
  t.flute_length = 8;
  t.shank = {4, 8};
  t.holder = {12, 20};
  return t;
}

const std::vector<config::ToolType> kTypes = {config::ToolType::Flat, config::ToolType::Ball, config::ToolType::Bull};

std::string name_of(config::ToolType type) { return std::string(config::to_string(type)); }

const AxialBody& axial(const geometry::StructuringElement& e) { return std::get<AxialBody>(e); }

TEST(Cutter, ThePlannersInstrumentAndTheSimulatorsCutterHaveOneProfile) {
  for (const config::ToolType type : kTypes) {
    SCOPED_TRACE(name_of(type));
    const config::CuttingTool tool = tool_of(type);
    const planner::Instrument planned = planner::tool_instrument(tool, config::Approach::PlusZ);
    const sim::Cutter simulated = sim::cutter_of(tool);
    ASSERT_EQ(planned.cutting.size(), 1u);
    ASSERT_EQ(planned.body.size(), 1u);
    EXPECT_EQ(axial(planned.cutting[0]).direction, (geometry::AxisDirection{geometry::Axis::Z, +1}));
    for (double z = 0; z <= 40; z += 1.0 / 16) {
      EXPECT_EQ(radius_squared_at(axial(planned.cutting[0]).sections, z), radius_squared_at(simulated.cutting, z)) << z;
      EXPECT_EQ(radius_squared_at(axial(planned.body[0]).sections, z), radius_squared_at(simulated.body, z)) << z;
    }
    // The cutter ends at the flutes with the tool's radius; the holder never ends.
    EXPECT_DOUBLE_EQ(radius_squared_at(simulated.cutting, 8), 4);
    EXPECT_LT(radius_squared_at(simulated.cutting, 8.01), 0);
    EXPECT_DOUBLE_EQ(radius_squared_at(simulated.body, 1e9), 36);
    // From another side the planner lays the same profile along the approach.
    const planner::Instrument side = planner::tool_instrument(tool, config::Approach::MinusX);
    EXPECT_EQ(axial(side.cutting[0]).direction, (geometry::AxisDirection{geometry::Axis::X, -1}));
    EXPECT_EQ(axial(side.cutting[0]).sections.size(), simulated.cutting.size());
  }
}

TEST(Cutter, TheSimulatorsSweepBodyHoldsExactlyThePlannersVoxels) {
  const geometry::Lattice lattice{0.5, {0, 0, 0}};
  const Index3 tip{20, 20, 4};
  const geometry::Vec3 at{(tip.x + 0.5) * 0.5, (tip.y + 0.5) * 0.5, (tip.z + 0.5) * 0.5};
  const geometry::IndexBox domain{{0, 0, 0}, {41, 41, 4 + 60}};
  for (const config::ToolType type : kTypes) {
    SCOPED_TRACE(name_of(type));
    const config::CuttingTool tool = tool_of(type);
    const planner::Instrument planned = planner::tool_instrument(tool, config::Approach::PlusZ);
    const sim::Cutter simulated = sim::cutter_of(tool);
    for (const bool body : {false, true}) {
      SCOPED_TRACE(body ? "body" : "cutting part");
      std::set<std::tuple<int, int, int>> planner_voxels, sim_voxels;
      for (const Index3 d : geometry::offsets_of(body ? planned.body[0] : planned.cutting[0], lattice.voxel_size, 60))
        planner_voxels.insert({tip.x + d.x, tip.y + d.y, tip.z + d.z});
      const auto pieces = sim::pieces_of(body ? simulated.body : simulated.cutting);
      sim::swept_volume(pieces, {at, at}, lattice, domain).for_each_voxel([&](Index3 v) {
        sim_voxels.insert({v.x, v.y, v.z});
      });
      EXPECT_FALSE(sim_voxels.empty());
      EXPECT_EQ(planner_voxels, sim_voxels);
    }
  }
}

// The guard's offsets at level t, and the exact profile's with the tip `s` mm above a
// voxel centre, over columns within `reach` voxels of the axis and levels [0, levels).
std::set<std::tuple<int, int, int>> exact_offsets(const std::vector<AxialSection>& profile, double h, double s, int reach,
                                                  int levels) {
  std::set<std::tuple<int, int, int>> out;
  for (int t = 0; t < levels; ++t) {
    const double r2 = radius_squared_at(profile, t * h - s);
    for (int dy = -reach; dy <= reach; ++dy)
      for (int dx = -reach; dx <= reach; ++dx)
        if (r2 >= 0 && double(dx * dx + dy * dy) * h * h <= r2) out.insert({dx, dy, t});
  }
  return out;
}

TEST(Cutter, TheGuardHoldsTheToolUpToOneVoxelAboveALevelAndIsNoLarger) {
  config::CuttingTool necked = tool_of(config::ToolType::Flat);
  necked.shank = {3, 6};  // narrower above the flutes: the guard follows the exact profile down
  std::vector<config::CuttingTool> tools;
  for (const config::ToolType type : kTypes) tools.push_back(tool_of(type));
  tools.push_back(necked);
  for (const config::CuttingTool& tool : tools) {
    for (const double h : {0.5, 0.3}) {
      SCOPED_TRACE(name_of(tool.type) + " shank " + std::to_string(tool.shank.diameter) + " h " + std::to_string(h));
      const std::vector<AxialSection> profile = cutter_of(tool).whole();
      const AxialBody guard = conservative_guard(profile, h);
      EXPECT_EQ(guard.direction, (geometry::AxisDirection{geometry::Axis::Z, +1}));
      const int levels = int(std::ceil((tool.flute_length + tool.shank.length) / h)) + 6;
      for (int t = 0; t < levels; ++t) {
        const double g2 = radius_squared_at(guard.sections, t * h);
        // The exact profile over [(t - 1) h, t h]: fine samples, its sections' ends and centres.
        std::vector<double> heights;
        for (int i = 0; i <= 256; ++i) heights.push_back(t * h - h * i / 256);
        for (const AxialSection& s : profile)
          for (const double v : {s.from, s.to, s.centre})
            if (v >= (t - 1) * h && v <= t * h) heights.push_back(v);
        double widest = -1;
        for (const double z : heights) {
          const double e2 = radius_squared_at(profile, z);
          EXPECT_LE(e2, g2 + 1e-9) << "level " << t << " z " << z;
          widest = std::max(widest, e2);
        }
        EXPECT_LE(g2, widest + 1e-9) << "level " << t << ": wider than the tool within a voxel below it";
      }
      // On the lattice: the guard's voxels hold the tool's at every tip height up to one
      // voxel above the level.
      const int reach = int(std::floor(tool.holder.diameter / 2 / h)) + 1;
      std::set<std::tuple<int, int, int>> guarded;
      for (const Index3 d : geometry::offsets_of(guard, h, levels)) guarded.insert({d.x, d.y, d.z});
      for (int i = 0; i <= 8; ++i) {
        for (const auto& v : exact_offsets(profile, h, h * i / 8, reach, levels))
          EXPECT_TRUE(guarded.count(v)) << "tip " << i << "/8 voxel up: offset " << std::get<0>(v) << " "
                                        << std::get<1>(v) << " " << std::get<2>(v) << " not guarded";
      }
    }
  }
}

TEST(Cutter, AHandBuiltToolTakesTheMachineFilesDefaults) {
  config::CuttingTool t;
  t.number = 3;
  t.type = config::ToolType::Ball;
  t.diameter = 6;
  t.holder = {};
  const config::CuttingTool d = with_defaults(t);
  EXPECT_EQ(d.flute_length, 18);
  EXPECT_EQ(d.shank.diameter, 6);
  EXPECT_EQ(d.shank.length, 12);
  EXPECT_EQ(d.holder.diameter, 50);
  EXPECT_EQ(d.holder.length, 60);
  EXPECT_EQ(d.step_down, 3);
  EXPECT_DOUBLE_EQ(d.step_over, 2.4);
  EXPECT_EQ(d.corner_radius, 3);
  const Cutter c = cutter_of(t);
  EXPECT_EQ(c.body[0].from, 18);
  EXPECT_EQ(c.body[1].from, 30);
  EXPECT_EQ(c.body[1].radius, 25);
  config::CuttingTool bull = t;
  bull.type = config::ToolType::Bull;
  bull.corner_radius = 3;
  EXPECT_THROW(with_defaults(bull), std::invalid_argument);
  EXPECT_THROW(with_defaults(config::CuttingTool{}), std::invalid_argument);
}

}  // namespace
}  // namespace hybridctl::instruments
