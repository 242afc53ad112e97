// A refusal in a shop's words (planner/pipeline/shop_words.hpp), on the B-axis machine
// (setups +Z, +X, -X, +Y; its smallest cutter 4 mm): the lidded channel block's channel is
// a closed space, the thin-wall block's 2.5 mm slot is narrower than any cutter; what the
// shop would change is said with it.

#include <gtest/gtest.h>

#include "planner/pipeline/shop_words.hpp"
#include "../../geometry/mesh_fixtures.hpp"
#include "proof_on_multitask.hpp"

namespace hybridctl::planner {
namespace {

using testing::kMultitask;

PlanningResult plan(const std::string& part) { return testing::proof_on_multitask(part); }

TEST(ShopWords, AClosedChannelIsAClosedSpaceNoCutterReaches) {
  const PlanningResult r = plan("lidded-channel-block");
  ASSERT_EQ(r.verdict.outcome, Verdict::Outcome::NotManufacturable) << r.verdict.summary;
  ASSERT_FALSE(r.in_shop_words.empty());
  const std::string& first = r.in_shop_words.front();
  EXPECT_EQ(first.rfind("closed space: a 205 mm\u00B3 cavity around (25.0, 14.6, 17.0) mm is closed in by the part on "
                        "every side: no cutter reaches it from any direction",
                        0),
            0u)
      << first;
  EXPECT_NE(first.find("an opening in the design, or the part made in two pieces, would do"), std::string::npos);
  // The same words as plan_part keeps them, for the machine it was planned on.
  EXPECT_EQ(refusal_in_shop_words(config::load_machine(kMultitask), r), r.in_shop_words);
}

// Milled only (the machine without its heads), the channel block's closed round channel
// is no atom of its own: no primitive parts it from the design round it, and the verdict
// names the regions that straddle the design. Their air is the channel, said once.
TEST(ShopWords, AClosedChannelSplitAmongRegionsThatStraddleTheDesignIsSaidOnce) {
  config::Machine milling = config::load_machine(kMultitask);
  milling.heads.clear();
  const PlanningResult r =
      plan_part(geometry::read_stl(testing::kParts + "channel-block.stl"), "channel-block", milling, PlanningOptions{});
  ASSERT_EQ(r.verdict.outcome, Verdict::Outcome::NotManufacturable) << r.verdict.summary;
  ASSERT_GT(r.verdict.violations.size(), 1u);
  ASSERT_EQ(r.in_shop_words.size(), 1u);
  const std::string& line = r.in_shop_words.front();
  EXPECT_EQ(line.rfind("closed space: ", 0), 0u) << line;
  EXPECT_NE(line.find(" regions around "), std::string::npos) << line;
  EXPECT_NE(line.find(" are closed in by the part on every side: no cutter reaches them"), std::string::npos) << line;
  // The channel is 8 mm across and 48 long: about 2,400 mm^3 of air.
  const double air = std::stod(line.substr(14));
  EXPECT_GT(air, 2200);
  EXPECT_LT(air, 2700);
}

TEST(ShopWords, ASlotNarrowerThanTheSmallestCutterSaysHowWideAndWhichCutter) {
  const PlanningResult r = plan("thin-wall-slot");
  ASSERT_EQ(r.verdict.outcome, Verdict::Outcome::NotManufacturable) << r.verdict.summary;
  ASSERT_FALSE(r.in_shop_words.empty());
  const std::string& first = r.in_shop_words.front();
  EXPECT_EQ(first.rfind("narrow slot: a 145 mm\u00B3 gap around (53.7, 14.9, 24.8) mm is 2.5 mm wide at most", 0), 0u) << first;
  EXPECT_NE(first.find("the smallest cutter, 4 mm flat detail (4 mm), does not fit; a cutter of 2.5 mm or less across would do"),
            std::string::npos)
      << first;
  // Its floor's and ends' regions are the same slot: said once.
  EXPECT_EQ(r.in_shop_words.size(), 1u);
}

// A 3-axis mill with only its +Z setup (hybrid-3axis without its bottom setup and heads),
// and a box milled from the plate stock, which stands 3 mm under the part: nothing but a
// setup from below, or from a side, reaches that margin.
TEST(ShopWords, StockUnderThePartWithoutASetupFromBelowIsTheUnderside) {
  config::Machine top_only = config::load_machine(HYBRIDCTL_SOURCE_DIR "/examples/machines/hybrid-3axis.yaml");
  top_only.heads.clear();
  std::erase_if(top_only.setups, [](const config::Setup& s) { return s.approach != config::Approach::PlusZ; });
  const PlanningResult r = plan_part(geometry::testing::box_mesh({0, 0, 0}, {20, 16, 10}), "box", top_only, PlanningOptions{});
  ASSERT_EQ(r.verdict.outcome, Verdict::Outcome::NotManufacturable) << r.verdict.summary;
  ASSERT_EQ(r.in_shop_words.size(), 1u);
  EXPECT_EQ(r.in_shop_words.front(),
            "underside: 3 mm of stock under the part around (9.9, 8.0, -1.5) mm can only be cut from +X, -X, +Y, -Y "
            "and -Z, and the machine has no setup from any of them; a stock flush with the part's bottom, or a setup "
            "from -Z, would do");
}

TEST(ShopWords, APartWithPlansNeedsNoWords) {
  PlanningResult r;
  r.verdict.outcome = Verdict::Outcome::Manufacturable;
  r.plans.push_back(Plan{});
  EXPECT_TRUE(refusal_in_shop_words(config::load_machine(kMultitask), r).empty());
}

}  // namespace
}  // namespace hybridctl::planner
