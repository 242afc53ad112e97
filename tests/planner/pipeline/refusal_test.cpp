// What a refusal names (plan_part's verdict from the proof before the search): the feature
// that makes the part impossible on the machine, not rows of voxels along its edges that
// only joined the proof on the way (planner/search/core_proof.hpp, docs/search.md).
//
// On multitask-b-axis (setups +Z, +X, -X, +Y; no access from below) the lidded channel
// block's closed channel is such a feature: air inside the raw stock that every cutter
// reaches only through the lid or the walls, which no deposit then makes again over the
// channel. Before, the verdict listed 27 atoms, the second of them a row of voxels along
// the block's bottom edge.

#include <gtest/gtest.h>

#include "proof_on_multitask.hpp"

namespace hybridctl::planner {
namespace {

using testing::kMultitask;

PlanningResult plan(const std::string& part) { return testing::proof_on_multitask(part); }

// A row of voxels along an edge of the bottom face (z = 0): one voxel high, one deep.
bool along_a_bottom_edge(const ViolatingAtom& v, const geometry::Box3& part) {
  const double voxel = 0.5 + 1e-9;
  const bool low = v.bounds.max.z <= part.min.z + voxel;
  const bool at_side = v.bounds.max.x <= part.min.x + voxel || v.bounds.min.x >= part.max.x - voxel ||
                       v.bounds.max.y <= part.min.y + voxel || v.bounds.min.y >= part.max.y - voxel;
  return low && at_side;
}

TEST(Refusal, TheLiddedChannelBlockIsRefusedForItsChannelAndNotForItsBottomEdges) {
  const PlanningResult r = plan("lidded-channel-block");
  ASSERT_EQ(r.verdict.outcome, Verdict::Outcome::NotManufacturable) << r.verdict.summary;
  ASSERT_EQ(r.core_proof.outcome, CoreProof::Outcome::Proven) << r.verdict.summary;
  ASSERT_FALSE(r.verdict.violations.empty());
  // First the channel: x 5..45, y 11..19, z 12..20, closed under a 4 mm lid.
  const ViolatingAtom& first = r.verdict.violations.front();
  EXPECT_TRUE(r.problem.atoms[std::size_t(first.atom)].must_out);
  EXPECT_GT(first.centroid.x, 5.0);
  EXPECT_LT(first.centroid.x, 45.0);
  EXPECT_GT(first.centroid.y, 11.0);
  EXPECT_LT(first.centroid.y, 19.0);
  EXPECT_GT(first.centroid.z, 12.0);
  EXPECT_LT(first.centroid.z, 20.0);
  EXPECT_NE(first.description.find("no removal reaches it without cutting the design"), std::string::npos)
      << first.description;
  EXPECT_NE(r.verdict.summary.find("no removal clears without cutting the design"), std::string::npos)
      << r.verdict.summary;
  // Every atom named is needed by the proof: without any one of them a projected plan exists.
  EXPECT_TRUE(projection_refutes(r.problem, r.core_proof.core, r.core_proof.groups));
  EXPECT_LT(r.core_proof.core.size(), std::size_t(r.core_proof.found));
  // The atoms the report lists (the first ten) include no bottom edge.
  const geometry::Box3 part = r.design.bounding_box_mm();
  for (std::size_t i = 0; i < r.verdict.violations.size() && i < 10; ++i)
    EXPECT_FALSE(along_a_bottom_edge(r.verdict.violations[i], part)) << r.verdict.violations[i].description;
}

// The gusset bracket's gussets meet the base plate and the upright in concave corners that
// no cutter of the machine clears to the tolerance: from +Z the 4 mm cutter's 6 mm shank
// meets the upright before its tip gets within a millimetre of it, and the larger cutters
// leave their radius in the corner against the gusset; from +X the shank meets the plate;
// from +Y the gussets stand in the way; there is no -Y setup. The refusal names such a
// corner beside a gusset, not the rows of voxels along the bottom edges it
// listed first before.
TEST(Refusal, TheGussetBracketIsRefusedForAGussetCornerNoCutterClears) {
  const PlanningResult r = plan("gusset-bracket");
  ASSERT_EQ(r.verdict.outcome, Verdict::Outcome::NotManufacturable) << r.verdict.summary;
  ASSERT_EQ(r.core_proof.outcome, CoreProof::Outcome::Proven) << r.verdict.summary;
  ASSERT_FALSE(r.verdict.violations.empty());
  const ViolatingAtom& first = r.verdict.violations.front();
  EXPECT_TRUE(cleared_only_by_cutting(r.problem, first.atom)) << first.description;
  // Beside the upright (x = 6) above the plate (z = 6), within the gussets' reach.
  EXPECT_GE(first.bounds.min.x, 6.0 - 1e-9);
  EXPECT_LE(first.bounds.max.x, 12.0);
  EXPECT_GE(first.bounds.min.z, 6.0 - 1e-9);
  EXPECT_LE(first.bounds.max.z, 16.0);
  const geometry::Box3 part = r.design.bounding_box_mm();
  for (std::size_t i = 0; i < r.verdict.violations.size() && i < 10; ++i) {
    const AtomSpec& spec = r.problem.atoms[std::size_t(r.verdict.violations[i].atom)];
    // The band's atoms come last; `plan` does not list them.
    if (spec.must_in || spec.must_out) {
      EXPECT_FALSE(along_a_bottom_edge(r.verdict.violations[i], part)) << r.verdict.violations[i].description;
    }
  }
}

}  // namespace
}  // namespace hybridctl::planner
