// Meshes for the report: coarsening keeps what most of each coarse voxel holds, the
// surface stays within its triangle budget and still encloses the solid, and the page's
// binary encoding is standard base64.

#include <gtest/gtest.h>

#include "geometry/shapes.hpp"
#include "geometry/mesh.hpp"
#include "report/report_mesh.hpp"

namespace hybridctl::report {
namespace {

using geometry::Index3;
using geometry::IndexBox;
using geometry::Lattice;
using geometry::Solid;

Solid box_solid(IndexBox box, double voxel = 0.5) {
  Solid s(Lattice{voxel, {0, 0, 0}}, box);
  for (int z = box.lo.z; z < box.hi.z; ++z)
    for (int y = box.lo.y; y < box.hi.y; ++y) s.set_run(y, z, box.lo.x, box.hi.x);
  return s;
}

double mesh_volume(const IndexedMesh& m) {
  double v = 0;
  for (std::size_t t = 0; t + 2 < m.indices.size(); t += 3) {
    const float* a = &m.positions[m.indices[t] * 3];
    const float* b = &m.positions[m.indices[t + 1] * 3];
    const float* c = &m.positions[m.indices[t + 2] * 3];
    v += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0])) / 6;
  }
  return v;
}

TEST(Coarsen, KeepsACoarseVoxelWhenAtLeastHalfOfItIsMaterial) {
  const Solid block = box_solid({{0, 0, 0}, {8, 8, 8}});
  const Solid coarse = coarsen(block, 2);
  EXPECT_EQ(coarse.voxel_size(), 1.0);
  EXPECT_EQ(coarse.voxel_count(), 64);
  EXPECT_DOUBLE_EQ(coarse.volume(), block.volume());
  Solid lone(block.lattice(), {{0, 0, 0}, {8, 8, 8}});
  lone.set({3, 3, 3});
  EXPECT_TRUE(coarsen(lone, 2).empty());  // one eighth of a coarse voxel
  const Solid half = box_solid({{-4, 0, 0}, {4, 8, 1}});  // the lower half of one coarse layer
  EXPECT_EQ(coarsen(half, 2).voxel_count(), 16);
  EXPECT_EQ(coarsen(half, 1), half);  // factor 1 is the solid itself
  const Solid thick = box_solid({{-4, 0, 0}, {4, 8, 2}});  // negative indices round down
  EXPECT_EQ(coarsen(thick, 2).bounding_box(), (IndexBox{{-2, 0, 0}, {2, 4, 1}}));
}

TEST(BudgetMesh, StaysWithinItsTriangleBudgetAndEnclosesTheSolid) {
  const Solid ball = geometry::make_sphere(Lattice{0.5, {0, 0, 0}}, {20, 20, 20}, 15);
  const IndexedMesh fine = budget_mesh(ball, 1'000'000);
  EXPECT_EQ(fine.voxel_size, 0.5);
  EXPECT_GT(fine.triangles(), 2000u);
  for (const std::size_t budget : {4000u, 1000u}) {
    const IndexedMesh m = budget_mesh(ball, budget);
    EXPECT_LE(m.triangles(), budget);
    EXPECT_GT(m.triangles(), budget / 8) << "coarsened more than the budget asks";
    EXPECT_GT(m.voxel_size, 0.5);
    EXPECT_NEAR(mesh_volume(m), ball.volume(), 0.1 * ball.volume()) << "budget " << budget;
  }
  EXPECT_NEAR(mesh_volume(fine), ball.volume(), 0.05 * ball.volume());
  EXPECT_TRUE(budget_mesh(Solid(Lattice{0.5, {0, 0, 0}}, {}), 100).empty());
}

TEST(BudgetMesh, SharesVerticesBetweenTriangles) {
  const IndexedMesh m = budget_mesh(box_solid({{0, 0, 0}, {10, 10, 10}}), 100000);
  ASSERT_FALSE(m.empty());
  EXPECT_LT(m.positions.size() / 3, m.indices.size() / 2);  // a closed mesh has about half as many vertices as triangles
  // Outward and closed: its volume is the cube's, less the half-voxel chamfers along its edges.
  EXPECT_NEAR(mesh_volume(m), 125.0, 0.1 * 125.0);
}

TEST(Base64, IsTheStandardEncoding) {
  EXPECT_EQ(base64("", 0), "");
  EXPECT_EQ(base64("f", 1), "Zg==");
  EXPECT_EQ(base64("fo", 2), "Zm8=");
  EXPECT_EQ(base64("foo", 3), "Zm9v");
  EXPECT_EQ(base64("foobar", 6), "Zm9vYmFy");
  const unsigned char high[] = {0xff, 0xfe, 0x00};
  EXPECT_EQ(base64(high, 3), "//4A");
}

}  // namespace
}  // namespace hybridctl::report
