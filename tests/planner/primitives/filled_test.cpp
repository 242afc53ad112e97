// Filled deposits (planner/primitives/filled.hpp): a head's overfill with what it cannot
// build filled solid, column by column from its first layer, offered where the support
// cut took design and removals can open the filling again.

#include <gtest/gtest.h>

#include "config/machine_loader.hpp"
#include "geometry/shapes.hpp"
#include "planner/primitives/filled.hpp"
#include "planner/pipeline/memory_estimate.hpp"

namespace hybridctl::planner {
namespace {

using geometry::Axis;
using geometry::Index3;
using geometry::IndexBox;
using geometry::Lattice;
using geometry::Solid;

const Lattice kMm{1.0, {0, 0, 0}};

TEST(FilledDeposits, EachColumnIsFilledFromTheFirstLayerUpToItsHighestVoxel) {
  const IndexBox domain{{0, 0, 0}, {3, 1, 6}};
  Solid region(kMm, domain);
  for (Index3 v : {Index3{0, 0, 1}, Index3{0, 0, 4}, Index3{1, 0, 3}}) region.set(v);
  // Built from +Z: the first layer is z = 1, the region's lowest.
  const Solid up = column_filled(region, {Axis::Z, +1}, domain);
  Solid expected(kMm, domain);
  for (int z = 1; z <= 4; ++z) expected.set({0, 0, z});
  for (int z = 1; z <= 3; ++z) expected.set({1, 0, z});
  EXPECT_EQ(up, expected);
  // Built from -Z: the first layer is z = 4, the highest; each column down to its lowest voxel.
  const Solid down = column_filled(region, {Axis::Z, -1}, domain);
  Solid expected_down(kMm, domain);
  for (int z = 1; z <= 4; ++z) expected_down.set({0, 0, z});
  for (int z = 3; z <= 4; ++z) expected_down.set({1, 0, z});
  EXPECT_EQ(down, expected_down);
}

// A table: a slab over two legs, 12 mm apart, far past what the DED head bridges. The top
// O-AM loses the slab's middle and all above it; filled, the room under the slab is solid,
// and the cutters from below open it again: the filled deposit is offered, and it holds
// the whole design. The legs alone (nothing cut by support) get none.
TEST(FilledDeposits, ATableSlabTheHeadCannotBridgeIsFilledWhereTheCuttersFromBelowOpenIt) {
  const config::Machine machine = config::load_machine(HYBRIDCTL_SOURCE_DIR "/examples/machines/hybrid-3axis.yaml");
  const Lattice lattice{0.5, {0, 0, 0}};
  const Solid legs = unite(geometry::make_box(lattice, {{0, 0, 0}, {4, 10, 8}}), geometry::make_box(lattice, {{16, 0, 0}, {20, 10, 8}}));
  const Solid table = unite(legs, geometry::make_box(lattice, {{0, 0, 8}, {20, 10, 10}}));
  for (const bool with_slab : {true, false}) {
    const Solid& design = with_slab ? table : legs;
    const IndexBox domain = planning_domain(machine, lattice, design.bounding_box_mm(), machine.planning.tolerance);
    const std::vector<Primitive> primitives = machine_primitives(machine, design, domain);
    const std::vector<Primitive> filled = filled_primitives(machine, design, domain, primitives);
    if (!with_slab) {
      EXPECT_TRUE(filled.empty());
      continue;
    }
    ASSERT_EQ(filled.size(), 1u);
    EXPECT_EQ(filled[0].label, "O-AM ded from +Z (top), filled");
    EXPECT_EQ(filled[0].kind, PrimitiveKind::OAm);
    EXPECT_TRUE(subtract(design, filled[0].region).empty());
    // The O-AM it comes from lacks the slab's middle.
    const auto oam = std::find_if(primitives.begin(), primitives.end(), [](const Primitive& p) {
      return p.kind == PrimitiveKind::OAm && p.setup == "top";
    });
    ASSERT_NE(oam, primitives.end());
    EXPECT_FALSE(subtract(design, oam->region).empty());
    // Solid under the slab, between the legs.
    EXPECT_TRUE(filled[0].region.contains(lattice.centers_within({{9, 4, 3}, {11, 6, 5}}).lo));
  }
}

}  // namespace
}  // namespace hybridctl::planner
