// A machine's removal primitives are their definitions: on a small machine with side
// setups from all six directions and flat, ball, bull-nose and reduced-neck tools, every
// SM-max and SM-cons region machine_primitives computes (tools sharing work per axis)
// equals, voxel for voxel, subtractive_maximal / subtractive_conservative of that tool in
// that setup computed alone (primitive_shapes.hpp).

#include <gtest/gtest.h>

#include "common/error.hpp"
#include "config/machine_loader.hpp"
#include "geometry/shapes.hpp"
#include "planner/atoms/fine_graining.hpp"
#include "planner/primitives/machine_primitives.hpp"
#include "planner/pipeline/memory_estimate.hpp"

namespace hybridctl::planner {
namespace {

using namespace hybridctl::geometry;

constexpr const char* kMachine = R"(
name: six-sided
envelope:
  X: {travel: [-200, 200], max_feed: 10000, max_acceleration: 1000}
  Y: {travel: [-200, 200], max_feed: 10000, max_acceleration: 1000}
  Z: {travel: [-200, 200], max_feed: 10000, max_acceleration: 1000}
heads:
  - {name: ded, process: ded-powder, bead: {width: 1.0, height: 0.5}, nozzle: {diameter: 6, length: 20},
     feed: 600, codes: {on: M64 P0, off: M65 P0}, cost_per_mm3: 2, primitives: [o-am]}
tools:
  - {number: 1, name: flat, type: flat, diameter: 2, flute_length: 2, shank: {diameter: 2, length: 2},
     holder: {diameter: 5, length: 10}, spindle_speed: 8000, feed: 1000, plunge_feed: 300, step_down: 1, step_over: 1}
  - {number: 2, name: ball, type: ball, diameter: 2, flute_length: 3, shank: {diameter: 2, length: 1},
     holder: {diameter: 4, length: 10}, spindle_speed: 8000, feed: 1000, plunge_feed: 300, step_down: 1, step_over: 1}
  - {number: 3, name: bull, type: bull, diameter: 3, corner_radius: 0.5, flute_length: 2,
     shank: {diameter: 3, length: 2}, holder: {diameter: 6, length: 10},
     spindle_speed: 8000, feed: 1000, plunge_feed: 300, step_down: 1, step_over: 1}
  - {number: 4, name: reduced neck, type: flat, diameter: 2, flute_length: 1.5, shank: {diameter: 1, length: 2},
     holder: {diameter: 5, length: 10}, spindle_speed: 8000, feed: 1000, plunge_feed: 300, step_down: 1, step_over: 1}
setups:
  - {name: top, approach: +Z, work_offset: G54, work_origin: [0, 0, 0]}
  - {name: bottom, approach: -Z, work_offset: G55, work_origin: [0, 0, 0]}
  - {name: right, approach: +X, work_offset: G56, work_origin: [0, 0, 0]}
  - {name: left, approach: -X, work_offset: G57, work_origin: [0, 0, 0]}
  - {name: back, approach: +Y, work_offset: G58, work_origin: [0, 0, 0]}
  - {name: front, approach: -Y, work_offset: G59, work_origin: [0, 0, 0]}
raw_stocks:
  - {name: block, box: {margin: 2}}
planning: {voxel_size: 0.5, tolerance: 0.25}
)";

// A mushroom with a hole through its cap and a pocket in its stem: overhangs, a hole that
// a narrow tool reaches through and one a wide tool does not, from every side.
Solid mushroom(const Lattice& lattice) {
  Solid s = unite(make_box(lattice, {{3, 3, 0}, {7, 7, 6}}), make_box(lattice, {{0, 0, 6}, {10, 10, 8}}));
  s = subtract(s, make_cylinder(lattice, Axis::Z, {1.5, 5, 5}, 0.75, 4));
  return subtract(s, make_box(lattice, {{4, 2.5, 2}, {6, 4, 4}}));
}

TEST(MachinePrimitives, EveryRemovalRegionEqualsItsDefinitionFromEverySide) {
  const config::Machine machine = config::parse_machine(kMachine, "six-sided.yaml");
  const Lattice lattice{machine.planning.voxel_size, {0, 0, 0}};
  const Solid design = mushroom(lattice);
  const IndexBox domain = planning_domain(machine, lattice, design.bounding_box_mm(), machine.planning.tolerance);
  const std::vector<Primitive> primitives = machine_primitives(machine, design, domain);

  int compared = 0;
  for (const Primitive& p : primitives) {
    if (p.mode != Mode::Subtractive) continue;
    const config::CuttingTool* tool = nullptr;
    for (const auto& t : machine.tools)
      if (t.number == p.tool_number) tool = &t;
    const config::Setup* setup = nullptr;
    for (const auto& s : machine.setups)
      if (s.name == p.setup) setup = &s;
    ASSERT_TRUE(tool && setup) << p.label;
    const Instrument in = tool_instrument(*tool, setup->approach);
    const Solid expected = p.kind == PrimitiveKind::SmMax ? subtractive_maximal(design, in, domain)
                                                          : subtractive_conservative(design, in, domain);
    EXPECT_EQ(p.region, expected) << p.label;
    // Never empty, never the whole domain: the design is in the way of every tool.
    EXPECT_FALSE(p.region.empty()) << p.label;
    EXPECT_LT(p.region.voxel_count(), domain.voxel_count()) << p.label;
    ++compared;
  }
  EXPECT_EQ(compared, 4 * 6 * 2);
  EXPECT_EQ(primitives.size(), machine_primitive_count(machine));
}

// An overfill deposit (O-AM) covers the design by the head's machining allowance
// everywhere it builds: a block on the plate, deposited from the top with an allowance of
// 1 mm, has every voxel within 1 mm of it above the plate; without the allowance it has
// only what a bead leaves (half its width sideways, half its height up).
TEST(MachinePrimitives, AnOverfillDepositCoversTheDesignByTheMachiningAllowance) {
  config::Machine machine = config::parse_machine(kMachine, "six-sided.yaml");
  machine.setups.resize(1);
  machine.tools.clear();
  const Lattice lattice{machine.planning.voxel_size, {0, 0, 0}};
  const Solid design = make_box(lattice, {{0, 0, 0}, {6, 6, 4}});
  const IndexBox domain = planning_domain(machine, lattice, design.bounding_box_mm(), machine.planning.tolerance);
  const auto overfill = [&](double allowance) {
    machine.heads[0].machining_allowance = allowance;
    for (const Primitive& p : machine_primitives(machine, design, domain))
      if (p.kind == PrimitiveKind::OAm) return p.region;
    ADD_FAILURE() << "no O-AM";
    return Solid(lattice, domain);
  };
  const Solid grown = intersect(dilate(design, Ball{1.0}, domain), make_box(lattice, {{-5, -5, 0}, {11, 11, 9}}));
  EXPECT_EQ(subtract(grown, overfill(1.0)).voxel_count(), 0);
  EXPECT_GT(subtract(grown, overfill(0.0)).voxel_count(), 0);
}

// The memory check counts every primitive the machine offers over all its setups, and the
// banded ones it may add (two levels, each on one setup here: its deposit and its cutter),
// the filled deposits (one per head with an O-AM and setup), and the fine-grained ones (at
// most kMaxFineGrainedPrimitives), and says what takes the memory when a problem does not fit.
TEST(MachinePrimitives, TheMemoryCheckCountsEveryPrimitiveOfEverySetup) {
  const config::Machine machine = config::parse_machine(kMachine, "six-sided.yaml");
  config::Machine one_setup = machine;
  one_setup.setups.resize(1);
  const Box3 part{{0, 0, 0}, {10, 10, 8}};
  const PlanningMemory six = planning_memory(part, machine, 0.5, 0.25), one = planning_memory(part, one_setup, 0.5, 0.25);
  EXPECT_EQ(six.primitives, 1 + 6 * 1 + 6 * 4 * 2 + 2 * (1 + 1) + 6 * 1 + kMaxFineGrainedPrimitives);
  EXPECT_EQ(one.primitives, 1 + 1 * 1 + 1 * 4 * 2 + 2 * (1 + 1) + 1 * 1 + kMaxFineGrainedPrimitives);
  EXPECT_GT(six.total(), one.total());
  EXPECT_EQ(six.total() - one.total(), double(six.primitives - one.primitives) * six.voxel_set);
  try {
    check_planning_memory(part, machine, 0.5, 0.25, 1024 * 1024, "mushroom.stl");
    FAIL() << "a 1 MiB budget fits";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("planning mushroom.stl at 0.5 mm (81 primitives and 10 other voxel sets"), std::string::npos) << message;
    EXPECT_NE(message.find("over the budget of 1.0 MiB"), std::string::npos) << message;
  }
  EXPECT_NO_THROW(check_planning_memory(part, machine, 0.5, 0.25, std::uint64_t(six.total()) + 1, "mushroom.stl"));
}

}  // namespace
}  // namespace hybridctl::planner
