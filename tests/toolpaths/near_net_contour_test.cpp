// A near-net layer's contour, as a specification: its beads run on the design's exact
// section (half a bead in), not on the voxel staircase; only over the layer's region; the
// voxel contour stays where no exact axis is near; a convex corner moves out until the
// bead reaches the design's corner; a thin wall's middle, which no raster reaches, gets a
// second loop.

#include "toolpaths/near_net_contour.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "geometry/voxelize.hpp"
#include "toolpaths/contour_reach.hpp"
#include "toolpaths/slices.hpp"
#include "../geometry/mesh_fixtures.hpp"

namespace hybridctl::toolpaths {
namespace {

using geometry::Lattice;
using geometry::Vec3;
using Lines = std::vector<std::vector<Point2>>;

const Lattice kLattice{0.5, {0, 0, 0}};
const double kNoReach = std::numeric_limits<double>::infinity();

double distance_to_segment(Point2 p, Point2 a, Point2 b) {
  const double dx = b.x - a.x, dy = b.y - a.y, len2 = dx * dx + dy * dy;
  const double t = len2 > 0 ? std::clamp(((p.x - a.x) * dx + (p.y - a.y) * dy) / len2, 0.0, 1.0) : 0.0;
  return std::hypot(p.x - (a.x + t * dx), p.y - (a.y + t * dy));
}

Lines all_of(const NearNetContour& c) {
  Lines out = c.exact;
  out.insert(out.end(), c.voxel.begin(), c.voxel.end());
  return out;
}

double distance_to_lines(Point2 p, const Lines& lines) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& line : lines)
    for (std::size_t i = 1; i < line.size(); ++i) best = std::min(best, distance_to_segment(p, line[i - 1], line[i]));
  return best;
}

// The cells of voxel layer k of the design.
SliceMask layer_cells(const geometry::TriangleMesh& mesh, int k) {
  const geometry::Solid solid = geometry::voxelize(mesh, kLattice, "design");
  return slice_of(solid, k, solid.storage_box());
}

// The layer's voxel contour, as a deposit without the design lays it.
Lines voxel_chains(const SliceMask& region, double half_bead) {
  int out_of_reach = 0;
  const SliceMask none(region.x0(), region.y0(), region.nx(), region.ny());
  return voxel_contour(region, none, kLattice, half_bead, 1.5, {half_bead, half_bead}, out_of_reach);
}

// A 2.5 mm blade at 60 degrees to X, as the bladed disc's: on 0.5 mm voxels its faces are
// staircases and the voxel contour zigzags inside it. The contour runs on both faces, half
// a bead (less the slack) in, from end to end; no staircase chain is left.
TEST(NearNetContour, OnABladeAcrossTheGridTheBeadsRunOnBothFacesNotOnTheStaircase) {
  const double c = std::cos(std::numbers::pi / 3), s = std::sin(std::numbers::pi / 3);
  const Vec3 from{5, 5, 0}, to{5 + 14 * c, 5 + 14 * s, 0};
  const auto blade = geometry::testing::bar_mesh(from, to, 2.5, 0, 3);
  const SliceMask region = layer_cells(blade, 2);
  const double half_bead = 0.75, slack = 0.125;
  const TipKeepOut axes = section_shrunk(blade.triangles, {1.25}, half_bead - slack);
  const Lines chains = voxel_chains(region, half_bead);
  ASSERT_FALSE(chains.empty());
  const Lines contour = all_of(near_net_contour(axes, region, chains, kLattice, {half_bead, half_bead - slack, kNoReach, 1.5}));
  ASSERT_FALSE(contour.empty());
  for (const auto& line : contour)
    for (const Point2& p : line) EXPECT_LT(distance_to_lines(p, {axes.loops().front()}), 1e-6) << "off the exact axis";
  // Each face, a bead length from either end: a bead's axis within half a bead less the
  // slack of every point.
  const Point2 n{-s * 1.25, c * 1.25};
  double worst = 0, worst_on_voxels = 0;
  for (double t = 1.5; t <= 12.5; t += 0.1)
    for (double side : {-1.0, 1.0}) {
      const Point2 q{from.x + t * c + side * n.x, from.y + t * s + side * n.y};
      worst = std::max(worst, distance_to_lines(q, contour));
      worst_on_voxels = std::max(worst_on_voxels, distance_to_lines(q, chains));
    }
  EXPECT_LE(worst, half_bead - slack + 1e-3);
  EXPECT_GT(worst_on_voxels, half_bead + 0.25) << "the staircase leaves a face a quarter of a millimetre out of a bead";
}

// A block whose layer region is its left half only (the right half is there already): the
// loop is kept where it runs over the region, and the voxel chain along the region's edge
// against the material already there, far from any exact axis, stays.
TEST(NearNetContour, TheLoopRunsOnlyOverTheRegionAndTheVoxelContourStaysWhereNoExactAxisIs) {
  const auto block = geometry::testing::box_mesh({0, 0, 0}, {10, 10, 3});
  SliceMask region = layer_cells(block, 2);
  for (int y = region.y0(); y < region.y0() + region.ny(); ++y)
    for (int x = 10; x < region.x0() + region.nx(); ++x) region.set(x, y, false);  // x >= 5 mm
  const TipKeepOut axes = section_shrunk(block.triangles, {1.25}, 0.75);
  const Lines chains = {{{4.25, 1.0}, {4.25, 9.0}},    // along the region's edge at x = 5
                        {{0.75, 1.0}, {0.75, 9.0}}};   // along the design's wall at x = 0
  const Lines contour = all_of(near_net_contour(axes, region, chains, kLattice, {0.75, 0.75, kNoReach, 1.5}));
  bool edge_chain = false, wall_chain = false;
  for (const auto& line : contour)
    for (const Point2& p : line) {
      EXPECT_TRUE(region.at(int(std::floor(p.x / 0.5)), int(std::floor(p.y / 0.5)))) << p.x << ", " << p.y;
      if (std::abs(p.x - 4.25) < 1e-9 && std::abs(p.y - 5.0) < 3) edge_chain = true;
      if (std::abs(p.x - 0.75) < 1e-9 && p.y > 2 && p.y < 8) wall_chain = true;
    }
  EXPECT_TRUE(edge_chain) << "the region's edge against material already there keeps its voxel contour";
  EXPECT_FALSE(wall_chain) << "the wall's voxel chain is the exact loop's to lay";
  EXPECT_LT(distance_to_lines({0.75, 5}, contour), 1e-6) << "the exact loop along the wall";
}

// A 2.5 mm blade and a 1.2 mm bead half a bead (less 0.025 mm) in from each face: the two
// beads' axes 1.35 mm apart leave 0.15 mm between them, which rasters across the blade
// only cross. A second loop half a bead further in lays it; a block as wide as many hatch
// spacings, whose middle the rasters fill, gets none.
TEST(NearNetContour, AThinWallsMiddleThatRastersOnlyCrossGetsASecondLoop) {
  const auto blade = geometry::testing::bar_mesh({2, 5, 0}, {18, 5, 0}, 2.5, 0, 3);
  const SliceMask region = layer_cells(blade, 2);
  const double half_bead = 0.6, hatch = 0.84;
  const NearNetBead bead{half_bead, half_bead - 0.025, kNoReach, 1.0};
  const TipKeepOut axes = section_shrunk(blade.triangles, {1.25}, bead.axis_inset);
  const Lines faces = near_net_contour(axes, region, {}, kLattice, bead).exact;
  EXPECT_GT(distance_to_lines({10, 5}, faces), half_bead) << "the faces' beads leave the middle";
  const Lines middle = near_net_gap_loops(axes, region, kLattice, bead, hatch);
  for (double x = 3; x <= 17; x += 0.1) EXPECT_LE(distance_to_lines({x, 5}, middle), half_bead) << x;
  const auto block = geometry::testing::box_mesh({2, 2, 0}, {18, 12, 3});
  const TipKeepOut block_axes = section_shrunk(block.triangles, {1.25}, bead.axis_inset);
  EXPECT_TRUE(near_net_gap_loops(block_axes, layer_cells(block, 2), kLattice, bead, hatch).empty());
}

// A 1.2 mm bead half a bead less 0.025 mm inside an L's faces: at the L's convex corners
// its axis turns 0.81 mm from the design's corner, and the bead falls 0.21 mm short of it.
// Asked to reach within 0.625 mm, each convex corner moves out along its bisector until it
// does; the inside corner stays, and with no reach asked nothing moves.
TEST(NearNetContour, AConvexCornerMovesOutUntilTheBeadReachesTheDesignsCorner) {
  const double a = 0.575;
  // The L [0, 10] x [0, 4] with [0, 4] x [4, 10], shrunk by a; clockwise (region on the right).
  const std::vector<Point2> loop = {{a, a}, {a, 10 - a}, {4 - a, 10 - a}, {4 - a, 4 - a}, {10 - a, 4 - a}, {10 - a, a}};
  const std::vector<Point2> design_corners = {{0, 0}, {0, 10}, {4, 10}, {4, 4}, {10, 4}, {10, 0}};
  const std::vector<Point2> moved = corners_reaching(loop, {0.6, a, 0.625, 1.0});
  // Five convex corners, each a detour of three points.
  ASSERT_EQ(moved.size(), loop.size() + 5 * 2);
  std::size_t k = 0;
  for (std::size_t i = 0; i < loop.size(); ++i) {
    if (i == 3) {
      EXPECT_EQ(moved[k++], loop[i]) << "the inside corner";
      continue;
    }
    const Point2 before = moved[k], tip = moved[k + 1], after = moved[k + 2];
    k += 3;
    EXPECT_NEAR(std::hypot(loop[i].x - design_corners[i].x, loop[i].y - design_corners[i].y), a * std::sqrt(2.0), 1e-9);
    EXPECT_NEAR(std::hypot(tip.x - design_corners[i].x, tip.y - design_corners[i].y), 0.625, 1e-9) << "corner " << i;
    // Along the bisector: as far from either face.
    EXPECT_NEAR(std::abs(tip.x - design_corners[i].x), std::abs(tip.y - design_corners[i].y), 1e-9);
    // The detour leaves and rejoins the sides half a bead in.
    for (Point2 side : {before, after})
      EXPECT_NEAR(std::min(std::abs(side.x - design_corners[i].x), std::abs(side.y - design_corners[i].y)), a, 1e-9);
  }
  EXPECT_EQ(corners_reaching(loop, {0.6, a, kNoReach, 1.0}), loop);
}

// A layer follows the section in the middle of the height over which its bead is full
// width: on a face leaning over the layer, the staircase then straddles the face. Where a
// flat face lies within the layer (a step), the layer holds the part above or below it, as
// its voxel centres do, and follows their sections.
TEST(NearNetSectionHeights, TheMiddleOfTheBeadsFullWidthUnlessAFlatFaceLiesWithinTheLayer) {
  const geometry::TriangleMesh step = geometry::testing::joined(geometry::testing::box_mesh({0, 0, 0}, {20, 20, 10}),
                                                       geometry::testing::box_mesh({5, 5, 10}, {15, 15, 20}));
  // A 0.75 mm bead in 0.6 mm layers is full width up to 0.375 mm: its middle, 0.1875 up.
  const std::vector<double> plain = near_net_section_heights(step.triangles, 4.0, 0.6, 0.75, kLattice);
  ASSERT_EQ(plain.size(), 1u);
  EXPECT_NEAR(plain[0], 4.1875, 1e-12);
  // A bead full width over the whole layer: the layer's middle.
  EXPECT_NEAR(near_net_section_heights(step.triangles, 4.0, 0.3, 0.75, kLattice).at(0), 4.15, 1e-12);
  // The step's top at z = 10 lies within [9.8, 10.4]: the voxel centre 10.25 (above it) only.
  EXPECT_EQ(near_net_section_heights(step.triangles, 9.8, 0.6, 0.75, kLattice), std::vector<double>{10.25});
  // A layer that ends on the flat face is not crossed by it.
  EXPECT_EQ(near_net_section_heights(step.triangles, 9.4, 0.6, 0.75, kLattice).size(), 1u);
}

}  // namespace
}  // namespace hybridctl::toolpaths
