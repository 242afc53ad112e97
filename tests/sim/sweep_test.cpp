// The swept volume of a body along a segment is exact at voxel resolution: a voxel is in
// it iff its centre lies in the body placed somewhere on the segment.
//  - Axis-aligned moves between voxel centres: the continuous sweep equals the Minkowski
//    sum of the path's voxels with the body (geometry::dilate, brute force), voxel for
//    voxel, because the nearest placement to any voxel centre is itself a voxel centre.
//  - Any other move (diagonals, ramps): the sweep lies between two dense placements of
//    the body along the segment, one of the body as is (every placement is on the
//    segment, so that union is inside the sweep) and one of the body grown by half the
//    sample spacing (every point of the segment is that close to a sample).

#include <gtest/gtest.h>

#include <random>

#include "sim/sweep.hpp"
#include "sim_fixtures.hpp"

namespace hybridctl::sim {
namespace {

using namespace testing;
using geometry::Vec3;

const IndexBox kDomain{{-20, -20, -20}, {60, 50, 50}};

Vec3 at(int i, int j, int k) { return kLattice.center({i, j, k}); }

// The voxels on the straight line between two voxels that differ along one axis.
Solid path_voxels(geometry::Index3 a, geometry::Index3 b) {
  Solid path(kLattice, kDomain);
  const geometry::Index3 lo{std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)};
  const geometry::Index3 hi{std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)};
  for (int z = lo.z; z <= hi.z; ++z)
    for (int y = lo.y; y <= hi.y; ++y)
      for (int x = lo.x; x <= hi.x; ++x) path.set({x, y, z});
  return path;
}

struct Tool {
  const char* name;
  std::vector<AxialSection> sections;
};

std::vector<Tool> tools() {
  std::vector<AxialSection> with_body = flat_mill(1.0, 3.0);
  for (const AxialSection& s : shank_and_holder()) with_body.push_back(s);
  return {{"flat r=2", flat_mill()},
          {"flat r=1.3 flute 2.2", flat_mill(1.3, 2.2)},
          {"ball r=1.5", ball_mill()},
          {"ball r=1.25", ball_mill(1.25, 3.0)},
          {"bull r=1.75 corner 0.75", bull_mill()},
          {"bull r=2 corner 0.5", bull_mill(2.0, 0.5, 2.5)},
          {"flat with shank and holder", with_body}};
}

Solid ours(const std::vector<AxialSection>& sections, Vec3 from, Vec3 to) {
  return swept_volume(pieces_of(sections), {from, to}, kLattice, kDomain);
}

TEST(SweptVolume, AxisAlignedMovesEqualTheDilationOfTheirPath) {
  const std::vector<std::pair<geometry::Index3, geometry::Index3>> moves = {
      {{4, 6, 2}, {14, 6, 2}},   // +X
      {{14, 6, 2}, {4, 6, 2}},   // -X
      {{5, 3, 1}, {5, 12, 1}},   // +Y
      {{5, 12, 1}, {5, 3, 1}},   // -Y
      {{6, 6, 9}, {6, 6, 1}},    // plunge
      {{6, 6, 1}, {6, 6, 9}},    // retract
      {{6, 6, 3}, {6, 6, 3}},    // standing still
  };
  for (const Tool& tool : tools()) {
    const geometry::AxialBody body{{geometry::Axis::Z, +1}, tool.sections};
    for (const auto& [a, b] : moves) {
      const Solid expected =
          geometry::dilate(path_voxels(a, b), body, kDomain, geometry::MorphologyMethod::BruteForce);
      const Solid got = ours(tool.sections, at(a.x, a.y, a.z), at(b.x, b.y, b.z));
      EXPECT_GT(got.voxel_count(), 0);
      EXPECT_EQ(got, expected) << tool.name << " from (" << a.x << "," << a.y << "," << a.z << ") to (" << b.x << ","
                               << b.y << "," << b.z << "): " << got.voxel_count() << " vs "
                               << expected.voxel_count() << " voxels";
    }
  }
}

TEST(SweptVolume, LevelBeadMovesEqualTheDilationOfTheirPath) {
  // Ellipsoid 2 x 1 mm: centre 0.5 mm = one voxel above the programmed (bottom) point,
  // and below it the cylinder of its width.
  const Bead ellipsoid{config::BeadShape::Ellipsoid, 2.0, 1.0, {}, {}};
  const Bead cylinder{config::BeadShape::Cylinder, 2.5, 1.5, {}, {}};
  for (const auto& [a, b] : std::vector<std::pair<geometry::Index3, geometry::Index3>>{
           {{2, 4, 3}, {15, 4, 3}}, {{3, 15, 0}, {3, 2, 0}}, {{7, 7, 7}, {7, 7, 7}}}) {
    const Solid path = path_voxels(a, b);
    const Solid expected_ellipsoid = geometry::unite(
        geometry::translate(
            geometry::dilate(path, geometry::Ellipsoid{{1.0, 1.0, 0.5}}, kDomain, geometry::MorphologyMethod::BruteForce),
            {0, 0, 1}),
        geometry::dilate(path, geometry::cylinder_body({geometry::Axis::Z, +1}, 1.0, 0.5), kDomain,
                         geometry::MorphologyMethod::BruteForce));
    const Solid expected_cylinder = geometry::dilate(path, geometry::cylinder_body({geometry::Axis::Z, +1}, 1.25, 1.5),
                                                     kDomain, geometry::MorphologyMethod::BruteForce);
    const Segment seg{at(a.x, a.y, a.z), at(b.x, b.y, b.z)};
    EXPECT_EQ(swept_volume(pieces_of(ellipsoid), seg, kLattice, kDomain), expected_ellipsoid);
    EXPECT_EQ(swept_volume(pieces_of(cylinder), seg, kLattice, kDomain), expected_cylinder);
  }
}

// The sandwich for an arbitrary segment; returns the number of voxels of the sweep.
void expect_between_dense_placements(const char* name, const std::function<ShapeTest(double)>& shape, double reach,
                                     double zlo, double zhi, const Solid& got, Vec3 a, Vec3 b) {
  const int n = 1200;
  const double delta = distance(a, b) / (2 * n) + 1e-9;
  const Solid inner = placed_union(shape(0), samples(a, b, n), reach, zlo, zhi, kDomain);
  const Solid outer = placed_union(shape(delta), samples(a, b, n), reach + delta, zlo - delta, zhi + delta, kDomain);
  ASSERT_GT(inner.voxel_count(), 0);
  // Not vacuous: the bounds are a few boundary voxels apart. (Segments are off the
  // lattice's rows: a segment parallel to a row at exactly the tool radius would put the
  // whole row on the boundary, inside the sweep but missed by most sample sets.)
  EXPECT_LT(outer.voxel_count() - inner.voxel_count(), inner.voxel_count() / 50 + 8) << name;
  EXPECT_TRUE(subset(inner, got)) << name << ": misses " << geometry::subtract(inner, got).voxel_count()
                                  << " voxels of the dense placements";
  EXPECT_TRUE(subset(got, outer)) << name << ": " << geometry::subtract(got, outer).voxel_count()
                                  << " voxels beyond the grown dense placements";
}

std::vector<std::pair<Vec3, Vec3>> general_segments() {
  std::vector<std::pair<Vec3, Vec3>> out = {
      {{1.1, 2.3, 1.0}, {8.7, 6.9, 1.0}},    // level diagonal, off the lattice
      {{2.0, 2.0, 6.0}, {9.0, 4.0, 1.0}},    // ramp down
      {{9.0, 4.0, 1.0}, {2.0, 2.0, 6.0}},    // ramp up
      {{3.0, 3.1, 1.0}, {9.5, 3.1, 1.6}},    // shallow ramp along X
      {{3.0, 3.0, 8.0}, {3.4, 3.3, 0.3}},    // steep ramp
      {{4.3, 5.1, 7.7}, {4.3, 5.1, 1.2}},    // off-lattice plunge
  };
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 10.0);
  for (int i = 0; i < 4; ++i) out.push_back({{u(rng), u(rng), u(rng)}, {u(rng), u(rng), u(rng)}});
  return out;
}

TEST(SweptVolume, AnySegmentLiesBetweenDensePlacementsOfTheTool) {
  for (const Tool& tool : tools()) {
    double reach = 0, top = 0;
    for (const AxialSection& s : tool.sections) {
      reach = std::max(reach, s.radius + s.ring);
      top = std::max(top, s.to);
    }
    for (const auto& [a, b] : general_segments()) {
      SCOPED_TRACE(std::string(tool.name) + " from (" + std::to_string(a.x) + "," + std::to_string(a.y) + "," +
                   std::to_string(a.z) + ") to (" + std::to_string(b.x) + "," + std::to_string(b.y) + "," +
                   std::to_string(b.z) + ")");
      expect_between_dense_placements(
          tool.name, [&](double delta) { return sections_shape(tool.sections, delta); }, reach, 0, top,
          ours(tool.sections, a, b), a, b);
    }
  }
}

TEST(SweptVolume, AnyBeadSegmentLiesBetweenDensePlacementsOfTheBead) {
  // 2.3 wide: its flat sides below the widest line are 1.15 from the axis, no lattice row's
  // distance from a segment along X at y = 3.1 (see below).
  const Bead bead{config::BeadShape::Ellipsoid, 2.3, 1.3, {}, {}};
  // Off the lattice's layers too: the bead's flat underside on a layer of voxel centres
  // would put that whole layer on the boundary (as for a row at exactly the radius).
  for (auto [a, b] : general_segments()) {
    a.z += 0.013, b.z += 0.013;
    SCOPED_TRACE("from (" + std::to_string(a.x) + "," + std::to_string(a.y) + "," + std::to_string(a.z) + ") to (" +
                 std::to_string(b.x) + "," + std::to_string(b.y) + "," + std::to_string(b.z) + ")");
    const Solid got = swept_volume(pieces_of(bead), {a, b}, kLattice, kDomain);
    expect_between_dense_placements(
        "ellipsoid bead", [&](double delta) { return ellipsoid_bead_shape(bead.width, bead.height, delta); }, 1.15, 0,
        1.3, got, a, b);
  }
}

TEST(SweptVolume, InfiniteBodiesNeedAClipBox) {
  const std::vector<AxialSection> holder = {{Kind::Cylinder, 5, std::numeric_limits<double>::infinity(), 3, 0, 0}};
  const std::vector<ConvexPiece> pieces = pieces_of(holder);
  const PieceSweep sweep(pieces.front(), {{0, 0, 0}, {1, 0, 0}}, kLattice);
  EXPECT_THROW((void)sweep.bounds(), std::invalid_argument);
  const IndexBox clip{{-10, -10, -10}, {10, 10, 30}};
  EXPECT_EQ(sweep.bounds(clip).hi.z, 30);
  const Solid swept = swept_volume(pieces, {{0, 0, 0}, {1, 0, 0}}, kLattice, clip);
  EXPECT_TRUE(swept.contains({0, 0, 29}));
  EXPECT_FALSE(swept.contains({0, 0, 9}));  // 4.5 mm: below the holder
  EXPECT_TRUE(swept.contains({0, 0, 10}));  // 5 mm: its bottom face
}

TEST(SweptVolume, BadSectionsAreRejected) {
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_THROW(pieces_of(std::vector<AxialSection>{{Kind::Sphere, 0, inf, 1, 1, 0}}), std::invalid_argument);
  EXPECT_THROW(pieces_of(std::vector<AxialSection>{{Kind::Cylinder, 0, 1, -1, 0, 0}}), std::invalid_argument);
  EXPECT_THROW(pieces_of(Bead{config::BeadShape::Ellipsoid, 0, 1, {}, {}}), std::invalid_argument);
  // An empty section (from > to) is dropped; a zero-ring torus is a sphere.
  EXPECT_TRUE(pieces_of(std::vector<AxialSection>{{Kind::Cylinder, 2, 1, 1, 0, 0}}).empty());
  EXPECT_EQ(pieces_of(std::vector<AxialSection>{{Kind::Torus, 0, 1, 1, 1, 0}}).front().kind, ConvexPiece::Kind::Sphere);
}

}  // namespace
}  // namespace hybridctl::sim
