// Inside corners no instrument makes (planner/pipeline/unreached_corners.hpp): the part is
// refused over a corner no cutter reaches only where no head lays a wall within the
// tolerance as deposited (its accuracy and half its layers' scallop), over a stretch that
// holds two layers of every head whose accuracy alone fits, and away from every raw
// stock's faces, which could be the finished face there.

#include "planner/pipeline/unreached_corners.hpp"

#include <gtest/gtest.h>

#include "config/machine_loader.hpp"

namespace hybridctl::planner {
namespace {

config::Machine example(const std::string& name) {
  return config::load_machine(HYBRIDCTL_SOURCE_DIR "/examples/machines/" + name + ".yaml");
}

TEST(WallsAsDeposited, AHeadLaysWallsWithinItsAccuracyAndHalfItsLayersScallop) {
  // The B-axis machine's powder head: 0.25 mm accuracy, 1.2 x 0.5 mm beads on 0.4 mm
  // layers, narrowing to 0.48 mm half-width under the next layer: 0.31 mm at best. The
  // wire-arc torch: 1 mm, its cylinder beads flat.
  const config::Machine multitask = example("multitask-b-axis");
  const WallsAsDeposited at_own = walls_as_deposited(multitask, 0.3);
  EXPECT_FALSE(at_own.within);
  EXPECT_NEAR(at_own.min_stretch, 2 * 0.4, 1e-9);  // the arc's accuracy alone is past 0.3 mm
  EXPECT_NE(at_own.said.find("ded within 0.31 mm (its accuracy 0.25 mm and half its layers' 0.12 mm scallop)"),
            std::string::npos)
      << at_own.said;
  EXPECT_NE(at_own.said.find("arc within 1 mm"), std::string::npos) << at_own.said;
  EXPECT_TRUE(walls_as_deposited(multitask, 0.32).within);
  // The 3-axis machine's head: 1.5 x 0.75 mm beads on 0.6 mm layers, 0.15 mm scallop.
  EXPECT_TRUE(walls_as_deposited(example("hybrid-3axis"), 0.5).within);
  EXPECT_FALSE(walls_as_deposited(example("hybrid-3axis"), 0.3).within);
}

// A result with a raw stock of [0, 20] mm cubed on 0.5 mm voxels, and a finder that names
// whatever corners it is given.
struct WithStock {
  PlanningResult r;
  WithStock() {
    r.lattice = {0.5, {0, 0, 0}};
    r.tolerance = 0.3;
    Primitive stock;
    stock.kind = PrimitiveKind::RawStock;
    stock.region = geometry::Solid::filled(r.lattice, {{0, 0, 0}, {40, 40, 40}});
    r.primitives.push_back(std::move(stock));
  }
};

plan::UnreachedCorner corner_at(double x, double y) { return {{x, y, 5}, {x, y, 8}, 90, 0.8, "T4 from +Z"}; }

plan::CornerFinder naming(std::vector<plan::UnreachedCorner> corners) {
  return [corners](const geometry::TriangleMesh&, double, double) { return corners; };
}

TEST(CornersNoInstrumentMakes, ACornerOnTheStocksFaceMayBeLeftAsTheStockHasIt) {
  const WithStock s;
  const WallsAsDeposited none{false, 0.8, ""};
  const auto found = corners_no_instrument_makes(s.r, none, naming({corner_at(10, 10), corner_at(20, 10)}));
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found.front().from.x, 10);
}

TEST(CornersNoInstrumentMakes, NoneWhereAHeadLaysWallsWithinTheTolerance) {
  const WithStock s;
  const WallsAsDeposited fits{true, 0.8, ""};
  EXPECT_TRUE(corners_no_instrument_makes(s.r, fits, naming({corner_at(10, 10)})).empty());
}

TEST(CornerRefusal, SaysTheCornersTheNearestCutterAndTheHeads) {
  const WallsAsDeposited none{false, 0.8, "ded within 0.31 mm"};
  const Verdict v = corner_refusal({corner_at(10, 10), corner_at(12, 10)}, none, 0.3);
  EXPECT_EQ(v.outcome, Verdict::Outcome::NotManufacturable);
  EXPECT_TRUE(v.decided_without_search);
  EXPECT_NE(v.summary.find("2 inside corners within the 0.3 mm tolerance"), std::string::npos) << v.summary;
  EXPECT_NE(v.summary.find("(10.00, 10.00) mm, z 5.0 to 8.0"), std::string::npos) << v.summary;
  EXPECT_NE(v.summary.find("T4 from +Z stays 0.8 mm off"), std::string::npos) << v.summary;
  EXPECT_NE(v.summary.find("ded within 0.31 mm"), std::string::npos) << v.summary;
}

}  // namespace
}  // namespace hybridctl::planner
