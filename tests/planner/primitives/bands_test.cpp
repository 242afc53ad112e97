// Banded primitives (planner/primitives/bands.hpp): where "mill up to here, deposit from here on"
// is offered, and that with it the best plan of a block with a closed channel mills the
// block up to the channel's floor and deposits only the band above it.

#include <gtest/gtest.h>

#include "config/machine_loader.hpp"
#include "geometry/mesh.hpp"
#include "geometry/solid.hpp"
#include "planner/primitives/bands.hpp"
#include "planner/pipeline/planning.hpp"

namespace hybridctl::planner {
namespace {

using geometry::Axis;
using geometry::Index3;
using geometry::IndexBox;
using geometry::Solid;

const geometry::Lattice kMm{1.0, {0, 0, 0}};
const geometry::AxisDirection kUp{Axis::Z, +1};
const geometry::AxisDirection kDown{Axis::Z, -1};

Solid box(Index3 lo, Index3 hi) { return Solid::filled(kMm, {lo, hi}); }

// A 20 x 20 x 20 block with a closed 6 x 6 x 6 cavity from z = 8 to 14.
struct ClosedCavity {
  Solid cavity = box({7, 7, 8}, {13, 13, 14});
  Solid design = subtract(box({0, 0, 0}, {20, 20, 20}), cavity);
};

TEST(BandLevels, AClosedCavitysLevelIsItsFloorAlongTheBuildDirection) {
  const ClosedCavity part;
  // Up: mill the block to z = 8, deposit from there. Down (the part turned over): mill it
  // from below to z = 14, deposit downwards from there.
  EXPECT_EQ(band_levels(part.design, part.cavity, kUp, {&part.design}),
            (std::vector<BandLevel>{{kUp, 8, "cavity floor"}}));
  EXPECT_EQ(band_levels(part.design, part.cavity, kDown, {&part.design}),
            (std::vector<BandLevel>{{kDown, 14, "cavity floor"}}));
}

TEST(BandLevels, NoCavityLevelWhenNoHeadBuildsAroundTheCavity) {
  const ClosedCavity part;
  // A deposit that lacks the cavity's roof (an overhang it cannot build) cannot close it.
  const Solid without_roof = subtract(part.design, box({7, 7, 14}, {13, 13, 15}));
  EXPECT_TRUE(band_levels(part.design, part.cavity, kUp, {&without_roof}).empty());
  EXPECT_TRUE(band_levels(part.design, part.cavity, kUp, {}).empty());
}

TEST(BandLevels, APlateUnderABossHasItsLevelAtThePlatesTopOnlyBuildingUp) {
  // A 30 x 30 x 5 plate with a 6 x 6 boss 15 tall on top: the section shrinks to 4 % at
  // z = 5 going up; going down it only grows.
  const Solid design = unite(box({0, 0, 0}, {30, 30, 5}), box({12, 12, 5}, {18, 18, 20}));
  const Solid none(kMm, {});
  EXPECT_EQ(band_levels(design, none, kUp, {&design}), (std::vector<BandLevel>{{kUp, 5, "section shrinks"}}));
  EXPECT_TRUE(band_levels(design, none, kDown, {&design}).empty());
}

TEST(BandLevels, SectionStepsRankByTheAreaTheyGiveUpAndAThinTipIsNone) {
  // Three steps up, each halving the section or more: 20x20, 10x20, 4x20, 1x20, 6 layers
  // each. The last tip holds 3 % of the part: no feature to deposit on its own.
  Solid design = box({0, 0, 0}, {20, 20, 6});
  design = unite(design, box({0, 0, 6}, {10, 20, 12}));
  design = unite(design, box({0, 0, 12}, {4, 20, 18}));
  design = unite(design, box({0, 0, 18}, {1, 20, 24}));
  const Solid none(kMm, {});
  const std::vector<BandLevel> levels = band_levels(design, none, kUp, {&design});
  ASSERT_EQ(levels.size(), 2u);
  EXPECT_EQ(levels[0].plane, 6);   // gives up 200 voxels a layer
  EXPECT_EQ(levels[1].plane, 12);  // 120
}

TEST(BandLevels, ASlotAcrossTheSectionIsNoStep) {
  // A 40 x 20 x 20 block with a 1 wide slot across it at x = 15..16, 10 deep from the top:
  // along +X the section halves at the slot and comes back after it.
  const Solid design = subtract(box({0, 0, 0}, {40, 20, 20}), box({15, 0, 10}, {16, 20, 20}));
  const Solid none(kMm, {});
  EXPECT_TRUE(band_levels(design, none, {Axis::X, +1}, {&design}).empty());
}

TEST(Beyond, IsTheSideOfTheLevelTheBuildGoesTo) {
  const IndexBox domain{{0, 0, 0}, {4, 4, 10}};
  EXPECT_EQ(beyond(kMm, domain, {kUp, 6, ""}), box({0, 0, 6}, {4, 4, 10}));
  EXPECT_EQ(beyond(kMm, domain, {kDown, 6, ""}), box({0, 0, 0}, {4, 4, 6}));
  EXPECT_TRUE(beyond(kMm, domain, {kUp, 12, ""}).empty());
}

// The bundled arch-channel block: 60 x 40 x 40, a closed channel whose floor is at
// z = 22 and whose pointed roof builds without support (examples/parts/README.md).
struct ArchChannel : ::testing::Test {
  // With `blank`, the machine also stocks a ground blank that sits flush with the part's
  // underside (a plate as thick as the part and 3 mm more): no facing from below, no
  // refixture.
  static config::Machine machine(bool blank = false) {
    config::Machine m = config::load_machine(HYBRIDCTL_SOURCE_DIR "/examples/machines/hybrid-3axis.yaml");
    if (blank) {
      config::RawStock ground{.name = "ground-blank", .kind = config::RawStock::Kind::Plate, .margin = {2, 2, 0}};
      ground.plate_thickness = 43;
      m.raw_stocks.push_back(ground);
    }
    return m;
  }
  static PlanningResult plan(bool bands, config::Objective objective = config::Objective::CostFactor, bool blank = false) {
    const config::Machine machine = ArchChannel::machine(blank);
    PlanningOptions options;
    options.bands = bands;
    options.top_k = 1;
    options.objective = objective;
    return plan_part(geometry::read_stl(HYBRIDCTL_SOURCE_DIR "/examples/parts/arch-channel-block.stl"), "arch-channel-block",
                     machine, options);
  }
};

TEST_F(ArchChannel, TheBestPlanMillsUpToTheChannelFloorAndDepositsOnlyTheBandAbove) {
  const PlanningResult r = plan(true);
  ASSERT_EQ(r.plans.size(), 1u) << r.verdict.summary;
  const Plan& best = r.plans[0];
  double deposited = 0;
  bool milled_to_floor = false;
  for (const PlanStep& step : best.steps) {
    const Primitive& p = r.primitives[std::size_t(step.primitive)];
    if (p.mode == Mode::Additive && p.kind != PrimitiveKind::RawStock) deposited += step.volume;
    milled_to_floor = milled_to_floor || p.label.find("down to z = 22 mm") != std::string::npos;
  }
  EXPECT_TRUE(milled_to_floor) << expression(r.problem, best);
  EXPECT_LE(deposited, 0.5 * r.design_volume);
  // Without bands the best the search finds mills far deeper (SM-cons cuts down past the
  // channel to get at it) and deposits more.
  const PlanningResult whole = plan(false);
  ASSERT_EQ(whole.plans.size(), 1u);
  EXPECT_LT(best.cost, whole.plans[0].cost);
}

// Priced as a shop prices it (docs/costs.md), from a ground blank flush with the part's
// underside, milling to the floor and depositing the band costs at most half of depositing
// the whole part with the same head, in machine time and in money: the whole-part
// deposit's estimate is taken in the same run. (From the box stock, whose 3 mm under the
// part must be faced after turning the part over by hand, 15 min of refixture make it 0.55.)
TEST_F(ArchChannel, InMinutesAndMoneyTheBestPlanCostsAtMostHalfOfDepositingTheWholePart) {
  for (const config::Objective objective : {config::Objective::Time, config::Objective::Money}) {
    SCOPED_TRACE(std::string(config::to_string(objective)));
    const PlanningResult r = plan(true, objective, true);
    ASSERT_EQ(r.plans.size(), 1u) << r.verdict.summary;
    const auto whole = std::find_if(r.primitives.begin(), r.primitives.end(), [](const Primitive& p) {
      return p.label == "U-AM ded from +Z (top)";
    });
    ASSERT_NE(whole, r.primitives.end());
    Plan deposit_all;
    deposit_all.steps = {{int(whole - r.primitives.begin()), whole->region.volume(), 0}};
    const Estimate all = estimate_plan(machine(true), r.primitives, deposit_all).total;
    const Estimate best = r.estimates.at(0).total;
    EXPECT_GE(whole->region.volume(), 0.9 * r.design_volume);  // it is the whole part
    EXPECT_LE(best.minutes, 0.5 * all.minutes) << expression(r.problem, r.plans[0]);
    EXPECT_LE(best.money, 0.5 * all.money) << expression(r.problem, r.plans[0]);
    EXPECT_DOUBLE_EQ(r.plans[0].cost, objective == config::Objective::Time ? best.minutes : best.money);
  }
}

}  // namespace
}  // namespace hybridctl::planner
