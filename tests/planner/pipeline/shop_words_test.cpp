// A refusal in a shop's words (planner/pipeline/shop_words.hpp), on the B-axis machine
// (setups +Z, +X, -X, +Y; its smallest cutter 4 mm): the lidded channel block's channel is
// a closed space, the thin-wall block's 2.5 mm slot is narrower than any cutter; on
// hybrid-3axis with only its +Z setup, the stock under a box is the underside and the
// chamfered cap's 60 degree underside an overhang past the powder head's 30; what the shop
// would change is said with it.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

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
  // The whole channel, 40 x 8 x 8 mm round (25, 15, 16), however the atoms split it.
  EXPECT_EQ(first.rfind("closed space: a 2560 mm\u00B3 cavity around (25.0, 15.0, 16.0) mm is closed in by the part on "
                        "every side: no cutter reaches it from any direction",
                        0),
            0u)
      << first;
  EXPECT_NE(first.find("an opening in the design, or the part made in two pieces, would do"), std::string::npos);
  // The lid over it is no overhang: its roof is the closed space's, said as that.
  EXPECT_EQ(r.in_shop_words.size(), 1u);
  // The same words as plan_part keeps them, for the machine it was planned on.
  EXPECT_EQ(refusal_in_shop_words(config::load_machine(kMultitask), r), r.in_shop_words);
}

// Milled only (the machine without its heads), the channel block's closed round channel
// is no atom of its own: no primitive parts it from the design round it, and the verdict
// names the regions that straddle the design. Their air is the channel, said once, whole.
TEST(ShopWords, AClosedChannelSplitAmongRegionsThatStraddleTheDesignIsSaidOnce) {
  config::Machine milling = config::load_machine(kMultitask);
  milling.heads.clear();
  const PlanningResult r =
      plan_part(geometry::read_stl(testing::kParts + "channel-block.stl"), "channel-block", milling, PlanningOptions{});
  ASSERT_EQ(r.verdict.outcome, Verdict::Outcome::NotManufacturable) << r.verdict.summary;
  ASSERT_GT(r.verdict.violations.size(), 1u);
  ASSERT_EQ(r.in_shop_words.size(), 1u);
  const std::string& line = r.in_shop_words.front();
  EXPECT_EQ(line.rfind("closed space: a ", 0), 0u) << line;
  EXPECT_NE(line.find(" cavity around "), std::string::npos) << line;
  EXPECT_NE(line.find(" is closed in by the part on every side: no cutter reaches it"), std::string::npos) << line;
  // The channel is 8 mm across and 48 long: about 2,400 mm^3 of air.
  const double air = std::stod(line.substr(16));
  EXPECT_GT(air, 2200);
  EXPECT_LT(air, 2700);
}

TEST(ShopWords, ASlotNarrowerThanTheSmallestCutterSaysHowWideAndWhichCutter) {
  const PlanningResult r = plan("thin-wall-slot");
  ASSERT_EQ(r.verdict.outcome, Verdict::Outcome::NotManufacturable) << r.verdict.summary;
  ASSERT_FALSE(r.in_shop_words.empty());
  const std::string& first = r.in_shop_words.front();
  // The whole slot, 2.5 x 40 x 12 mm round (53.75, 20, 24), however the atoms split it.
  EXPECT_EQ(first.rfind("narrow slot: a 1200 mm\u00B3 gap around (53.8, 20.0, 24.0) mm is 2.5 mm wide at most", 0), 0u) << first;
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

// hybrid-3axis with only its +Z setup: the powder head (support.max_overhang 30) builds
// from below, and the cutters reach nothing under the part.
config::Machine top_setup_only() {
  config::Machine m = config::load_machine(HYBRIDCTL_SOURCE_DIR "/examples/machines/hybrid-3axis.yaml");
  std::erase_if(m.setups, [](const config::Setup& s) { return s.approach != config::Approach::PlusZ; });
  return m;
}

// A 12 mm square post, 20 tall, under a square cap that hangs out on every side over a
// chamfer 6 mm tall leaning `lean_degrees` from the vertical, and stands 4 mm straight
// above it; its minimum corner at the origin: a cap like examples/parts/chamfered-cap.scad
// (which keeps the cap 33 mm across instead) for any lean.
geometry::TriangleMesh chamfered_cap(double lean_degrees) {
  const double out = 6 * std::tan(lean_degrees * std::numbers::pi / 180), c = 6 + out;
  const std::array<std::pair<double, double>, 4> rings{{{0, 6}, {20, 6}, {26, 6 + out}, {30, 6 + out}}};  // z, half width
  const auto corner = [&](std::size_t ring, int k) {
    const double w = rings[ring].second, sx = (k == 1 || k == 2) ? 1 : -1, sy = k >= 2 ? 1 : -1;
    return geometry::Vec3{c + sx * w, c + sy * w, rings[ring].first};
  };
  geometry::TriangleMesh m;
  m.triangles.push_back({corner(0, 0), corner(0, 2), corner(0, 1)});
  m.triangles.push_back({corner(0, 0), corner(0, 3), corner(0, 2)});
  m.triangles.push_back({corner(3, 0), corner(3, 1), corner(3, 2)});
  m.triangles.push_back({corner(3, 0), corner(3, 2), corner(3, 3)});
  for (std::size_t i = 0; i + 1 < rings.size(); ++i)
    for (int k = 0; k < 4; ++k) {
      const int n = (k + 1) % 4;
      m.triangles.push_back({corner(i, k), corner(i, n), corner(i + 1, n)});
      m.triangles.push_back({corner(i, k), corner(i + 1, n), corner(i + 1, k)});
    }
  EXPECT_GT(geometry::signed_volume(m), 0);  // outward
  return m;
}

// A T-section rail 30 mm long along Y: a 12 mm web, 20 tall, under a 33 mm flange whose
// undersides are chamfers leaning `lean_degrees` from the vertical, 4 mm straight above
// them; no outside corner where two chamfers meet. The profile in XZ is star-shaped from
// the web's top left corner, which fans the end faces.
geometry::TriangleMesh chamfered_rail(double lean_degrees) {
  const double rise = 10.5 / std::tan(lean_degrees * std::numbers::pi / 180), length = 30, top = 24 + rise;
  const std::vector<std::pair<double, double>> profile{{10.5, 0},  {22.5, 0}, {22.5, 20},    {33, 20 + rise},
                                                       {33, top}, {0, top},  {0, 20 + rise}, {10.5, 20}};
  const auto at = [&](std::size_t k, double y) { return geometry::Vec3{profile[k].first, y, profile[k].second}; };
  geometry::TriangleMesh m;
  const std::size_t n = profile.size(), fan = n - 1;
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t next = (k + 1) % n;
    m.triangles.push_back({at(k, 0), at(next, 0), at(next, length)});
    m.triangles.push_back({at(k, 0), at(next, length), at(k, length)});
    if (k != fan && next != fan) {
      m.triangles.push_back({at(fan, 0), at(next, 0), at(k, 0)});
      m.triangles.push_back({at(fan, length), at(k, length), at(next, length)});
    }
  }
  if (geometry::signed_volume(m) < 0)
    for (geometry::Triangle& t : m.triangles) std::swap(t[1], t[2]);
  return m;
}

std::vector<std::string> overhang_lines(const PlanningResult& r) {
  std::vector<std::string> lines;
  for (const std::string& line : r.in_shop_words)
    if (line.rfind("overhang: ", 0) == 0) lines.push_back(line);
  return lines;
}

// The chamfered cap (examples/parts/chamfered-cap.stl): its underside leans 60 degrees
// from the vertical, past the head's 30. Milled from the plate, the air under it is out of
// the +Z cutters' reach; deposited, the rule cuts the cap's rim. The lean is measured on
// the STL's faces, the limit read from the machine file.
TEST(ShopWords, AnUndersideLeaningPastTheHeadsLimitIsAnOverhangWithBothAngles) {
  const config::Machine machine = top_setup_only();
  const PlanningResult r =
      plan_part(geometry::read_stl(testing::kParts + "chamfered-cap.stl"), "chamfered-cap", machine, PlanningOptions{});
  ASSERT_NE(r.verdict.outcome, Verdict::Outcome::Manufacturable) << r.verdict.summary;
  const std::vector<std::string> lines = overhang_lines(r);
  ASSERT_EQ(lines.size(), 1u) << ::testing::PrintToString(r.in_shop_words);
  const std::string& line = lines.front();
  const std::size_t leans = line.find(" leans ");
  ASSERT_NE(leans, std::string::npos) << line;
  const double lean = std::stod(line.substr(leans + 7));
  EXPECT_NEAR(lean, 60, 2) << line;
  EXPECT_NE(line.find("\u00B0 from the build direction (+Z); the ded head builds at most 30\u00B0 (support.max_overhang)"),
            std::string::npos)
      << line;
  // Turned over, the head builds the whole part. No head rated for the lean is named: the
  // edges where two chamfers meet at the cap's corners lean 68 degrees, and one rated for
  // 62 leaves them.
  EXPECT_NE(line.find("; a setup from -Z, or support material, would do"), std::string::npos) << line;
  EXPECT_EQ(line.find("rated for"), std::string::npos) << line;
  // Around the middle of the underside, which runs round the post from z = 20 to 26.06.
  double x = 0, y = 0, z = 0;
  ASSERT_EQ(std::sscanf(line.c_str(), "overhang: the underside around (%lf, %lf, %lf) mm", &x, &y, &z), 3) << line;
  EXPECT_NEAR(x, 16.5, 1);
  EXPECT_NEAR(y, 16.5, 1);
  EXPECT_GT(z, 20);
  EXPECT_LT(z, 26.1);
  // A head rated past the lean builds the rim: the same refusal says no overhang of it.
  config::Machine rated = machine;
  rated.heads.front().support.max_overhang = 75;
  for (const std::string& said : refusal_in_shop_words(rated, r)) EXPECT_NE(said.rfind("overhang: ", 0), 0u) << said;
}

// The rail's chamfers meet no other chamfer: a head rated for their 60 degrees builds the
// flanges, and the line says so; so do setups along the rail (its section the same in
// every layer) and the one that turns it over.
TEST(ShopWords, AHeadRatedForTheLeanIsNamedWhereItBuildsTheOverhang) {
  const PlanningResult r = plan_part(chamfered_rail(60), "chamfered-rail", top_setup_only(), PlanningOptions{});
  ASSERT_NE(r.verdict.outcome, Verdict::Outcome::Manufacturable) << r.verdict.summary;
  const std::vector<std::string> lines = overhang_lines(r);
  ASSERT_EQ(lines.size(), 1u) << ::testing::PrintToString(r.in_shop_words);
  EXPECT_NE(lines.front().find(" mm leans 60\u00B0 from the build direction (+Z); the ded head builds at most 30\u00B0 "
                               "(support.max_overhang); a setup from +Y, -Y or -Z, support material, or a head rated "
                               "for 60\u00B0 would do"),
            std::string::npos)
      << lines.front();
}

// The same cap with a 20 degree chamfer: the head builds its underside; whatever stops
// the part, it is no overhang.
TEST(ShopWords, AnUndersideWithinTheHeadsLimitIsNoOverhang) {
  const PlanningResult r = plan_part(chamfered_cap(20), "chamfered-cap-20", top_setup_only(), PlanningOptions{});
  EXPECT_TRUE(overhang_lines(r).empty()) << ::testing::PrintToString(r.in_shop_words);
}

// The bundled mushroom (examples/parts/overhang.stl): its slab's underside is flat, which
// no head is rated for; turned over, the head builds it.
TEST(ShopWords, AFlatUndersideIsAnOverhangAtNinetyDegrees) {
  const PlanningResult r =
      plan_part(geometry::read_stl(testing::kParts + "overhang.stl"), "overhang", top_setup_only(), PlanningOptions{});
  ASSERT_NE(r.verdict.outcome, Verdict::Outcome::Manufacturable) << r.verdict.summary;
  const std::vector<std::string> lines = overhang_lines(r);
  ASSERT_EQ(lines.size(), 1u) << ::testing::PrintToString(r.in_shop_words);
  EXPECT_NE(lines.front().find(" mm is flat, 90\u00B0 from the build direction (+Z); the ded head builds at most 30\u00B0 "
                               "(support.max_overhang); a setup from -Z, or support material, would do"),
            std::string::npos)
      << lines.front();
}

TEST(ShopWords, APartWithPlansNeedsNoWords) {
  PlanningResult r;
  r.verdict.outcome = Verdict::Outcome::Manufacturable;
  r.plans.push_back(Plan{});
  EXPECT_TRUE(refusal_in_shop_words(config::load_machine(kMultitask), r).empty());
}

}  // namespace
}  // namespace hybridctl::planner
