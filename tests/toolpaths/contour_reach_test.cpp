// reach_edges (toolpaths/contour_reach.hpp): a deposition contour pulled out to the
// region's outermost voxel centres where the bead, through cell centres half a bead
// inside the edge, would not reach them; never so far that the bead at its widest holds
// the centre of a cell outside the region.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "toolpaths/contour_reach.hpp"
#include "toolpaths/slices.hpp"

namespace hybridctl::toolpaths {
namespace {

const geometry::Lattice kLattice{0.5, {0, 0, 0}};
constexpr double kH = 0.5;

Point2 centre(int x, int y) { return {(x + 0.5) * kH, (y + 0.5) * kH}; }

// A disc 15 mm across on the cells' centres: a staircase edge at every angle, as a
// bladed disc's rim.
SliceMask disc() {
  SliceMask m(0, 0, 40, 40);
  for (int y = 0; y < 40; ++y)
    for (int x = 0; x < 40; ++x)
      if (std::hypot(x - 19.5, y - 19.5) <= 15) m.set(x, y);
  return m;
}

SliceMask rectangle(int x0, int y0, int x1, int y1) {
  SliceMask m(0, 0, 40, 40);
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) m.set(x, y);
  return m;
}

// The contour as deposition_path builds it: the boundary of the region shrunk by half a
// bead, through cell centres.
std::vector<std::vector<Point2>> contour_of(const SliceMask& inner) {
  std::vector<std::vector<Point2>> chains;
  for (const auto& chain : trace_chains(boundary_cells(inner))) {
    chains.emplace_back();
    for (const Cell& c : chain) chains.back().push_back(centre(c.x, c.y));
  }
  return chains;
}

double distance(Point2 p, Point2 a, Point2 b) {
  const double abx = b.x - a.x, aby = b.y - a.y, ab2 = abx * abx + aby * aby;
  const double t = ab2 > 0 ? std::clamp(((p.x - a.x) * abx + (p.y - a.y) * aby) / ab2, 0.0, 1.0) : 0.0;
  return std::hypot(p.x - a.x - t * abx, p.y - a.y - t * aby);
}
double distance(Point2 p, const std::vector<std::vector<Point2>>& chains) {
  double d = std::numeric_limits<double>::infinity();
  for (const auto& ch : chains)
    for (std::size_t i = 0; i + 1 < ch.size(); ++i) d = std::min(d, distance(p, ch[i], ch[i + 1]));
  return d;
}

// The farthest cell of the region outside `inner` from the chains, mm.
double farthest_edge_cell(const SliceMask& region, const SliceMask& inner, const std::vector<std::vector<Point2>>& chains) {
  double worst = 0;
  for (int y = 0; y < 40; ++y)
    for (int x = 0; x < 40; ++x)
      if (region.at(x, y) && !inner.at(x, y)) worst = std::max(worst, distance(centre(x, y), chains));
  return worst;
}

int cells_farther_than(const SliceMask& region, const SliceMask& inner, const std::vector<std::vector<Point2>>& chains,
                       double mm) {
  int n = 0;
  for (int y = 0; y < 40; ++y)
    for (int x = 0; x < 40; ++x) n += region.at(x, y) && !inner.at(x, y) && distance(centre(x, y), chains) > mm;
  return n;
}

// The nearest any cell centre outside the region comes to the chains, mm.
double nearest_outside_cell(const SliceMask& region, const std::vector<std::vector<Point2>>& chains) {
  double nearest = std::numeric_limits<double>::infinity();
  for (int y = -2; y < 42; ++y)
    for (int x = -2; x < 42; ++x)
      if (!region.at(x, y)) nearest = std::min(nearest, distance(centre(x, y), chains));
  return nearest;
}

TEST(ContourReach, ARoundRimIsReachedByTheNarrowTopOfTheBead) {
  // The 1.5 x 0.75 mm bead, at the upper voxel of a band of two: 0.663 mm each side. Through
  // cell centres 1.5 voxels in, the contour passes 0.71 mm from the staircase's outermost
  // centres; pulled out, within reach, and still a half bead from every cell outside.
  const SliceMask region = disc(), inner = shrink_by_disc(region, 1.5);
  // A cell standing out of the staircase alone (outside cells on three sides) may stay
  // out of reach; such cells are counted, and the simulation of the bladed disc shows the
  // bead's lower, wider part lays them (toolpath_sim_test).
  auto chains = contour_of(inner);
  const int missed_before = cells_farther_than(region, inner, chains, 0.663);
  ASSERT_GT(missed_before, 20) << "the case shows nothing";
  const int missed = reach_edges(chains, region, inner, kLattice, {0.663, 0.75});
  EXPECT_EQ(missed, cells_farther_than(region, inner, chains, 0.663 - 0.005));
  EXPECT_LT(4 * missed, missed_before);
  EXPECT_GE(nearest_outside_cell(region, chains), 0.75);
}

TEST(ContourReach, ARectanglesCornersAreReachedAndItsEdgesLeftAlone) {
  // The 1.2 mm bead (0.6 mm each side): a straight edge's outermost centres lie 0.5 mm from
  // the contour, a corner's 0.71 mm. Only the corners move.
  const SliceMask region = rectangle(10, 10, 30, 20), inner = shrink_by_disc(region, 1.2);
  auto chains = contour_of(inner);
  const auto before = chains;
  ASSERT_GT(farthest_edge_cell(region, inner, chains), 0.6) << "the case shows nothing";
  EXPECT_EQ(reach_edges(chains, region, inner, kLattice, {0.6, 0.6}), 0);
  EXPECT_LE(farthest_edge_cell(region, inner, chains), 0.6);
  EXPECT_GE(nearest_outside_cell(region, chains), 0.6);
  int moved = 0;
  for (std::size_t c = 0; c < chains.size(); ++c)
    for (std::size_t i = 0; i < chains[c].size(); ++i)
      moved += chains[c][i].x != before[c][i].x || chains[c][i].y != before[c][i].y;
  EXPECT_GT(moved, 0);
  EXPECT_LE(moved, 4 + 1) << "only the four corners (a closed chain's first point twice)";
}

TEST(ContourReach, WhatTheBeadCannotReachWithoutLayingBeyondTheRegionIsCountedNotLaid) {
  // A bead that lays only 0.3 mm each side at the voxels' height but is 1.5 mm wide: the
  // contour cannot come within 0.3 mm of the edge's centres without its widest part
  // holding the centres outside. Those cells are counted; the clearance is kept.
  const SliceMask region = rectangle(10, 10, 30, 20), inner = shrink_by_disc(region, 1.5);
  auto chains = contour_of(inner);
  EXPECT_GT(reach_edges(chains, region, inner, kLattice, {0.3, 0.75}), 0);
  EXPECT_GE(nearest_outside_cell(region, chains), 0.75);
}

}  // namespace
}  // namespace hybridctl::toolpaths
