// Voxelization: a voxel is in the solid exactly when its centre is inside the mesh.
// Checked against exact analytic counts, an independent oracle (the generalized
// winding number), OpenVDB's own conversion, and the example parts' mesh volumes.

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "common/error.hpp"
#include "geometry/shapes.hpp"
#include "geometry/voxelize.hpp"
#include "mesh_fixtures.hpp"

namespace hybridctl::geometry {
namespace {

using testing::box_mesh;
using testing::joined;
using testing::sphere_mesh;

// Solid angle sum / 4 pi: 1 inside a closed outward mesh, 0 outside, whatever the
// facet order; independent of the scan conversion's rays and tie rules.
double winding_number(const TriangleMesh& mesh, Vec3 p) {
  double total = 0;
  for (const Triangle& t : mesh.triangles) {
    const Vec3 a{t[0].x - p.x, t[0].y - p.y, t[0].z - p.z};
    const Vec3 b{t[1].x - p.x, t[1].y - p.y, t[1].z - p.z};
    const Vec3 c{t[2].x - p.x, t[2].y - p.y, t[2].z - p.z};
    const double la = std::sqrt(a.x * a.x + a.y * a.y + a.z * a.z), lb = std::sqrt(b.x * b.x + b.y * b.y + b.z * b.z),
                 lc = std::sqrt(c.x * c.x + c.y * c.y + c.z * c.z);
    const double det = a.x * (b.y * c.z - b.z * c.y) - a.y * (b.x * c.z - b.z * c.x) + a.z * (b.x * c.y - b.y * c.x);
    const double ab = a.x * b.x + a.y * b.y + a.z * b.z, bc = b.x * c.x + b.y * c.y + b.z * c.z,
                 ca = c.x * a.x + c.y * a.y + c.z * a.z;
    total += 2 * std::atan2(det, la * lb * lc + ab * lc + bc * la + ca * lb);
  }
  return total / (4 * M_PI);
}

TEST(Voxelize, ABoxOnVoxelBoundariesIsExact) {
  const Lattice l{0.5, {0, 0, 0}};
  const Solid s = voxelize(box_mesh({1, 2, 3}, {11, 7, 4.5}), l, "box");
  EXPECT_EQ(s, make_box(l, {{1, 2, 3}, {11, 7, 4.5}}));
}

TEST(Voxelize, RaysThroughSharedEdgesAndVerticesCountOnce) {
  // Every row of centres passes exactly through the box's diagonal edges and corners
  // when the box is offset by half a voxel; a double count would punch holes.
  const Lattice l{1.0, {0, 0, 0}};
  const Solid s = voxelize(box_mesh({0.5, 0.5, 0.5}, {8.5, 6.5, 4.5}), l, "box");
  EXPECT_EQ(s, make_box(l, {{0.5, 0.5, 0.5}, {8.5, 6.5, 4.5}}));
  EXPECT_EQ(s.voxel_count(), 8 * 6 * 4);
}

TEST(Voxelize, AgreesWithTheWindingNumberOnEveryVoxelCentre) {
  // Two disjoint closed pieces, on a lattice skewed against every face.
  const TriangleMesh disjoint = joined(sphere_mesh({10, 10, 10}, 7.3, 12, 20), box_mesh({18, 2, 3}, {25.25, 9, 8.5}));
  const Lattice l{0.7, {0.13, -0.21, 0.05}};
  const Solid s = voxelize(disjoint, l, "pieces");
  const IndexBox domain = l.centers_within(bounds(disjoint));
  int disagreements = 0, inside = 0;
  for (int z = domain.lo.z; z < domain.hi.z; ++z)
    for (int y = domain.lo.y; y < domain.hi.y; ++y)
      for (int x = domain.lo.x; x < domain.hi.x; ++x) {
        const bool expected = winding_number(disjoint, l.center({x, y, z})) > 0.5;
        inside += expected;
        disagreements += expected != s.contains({x, y, z});
      }
  EXPECT_GT(inside, 1000);
  EXPECT_EQ(disagreements, 0);
}

TEST(Voxelize, FacetOrientationDoesNotMatter) {
  TriangleMesh flipped = sphere_mesh({0, 0, 0}, 5);
  for (std::size_t i = 0; i < flipped.triangles.size(); i += 3) std::swap(flipped.triangles[i][0], flipped.triangles[i][1]);
  const Lattice l{0.5, {0, 0, 0}};
  EXPECT_EQ(voxelize(flipped, l, "flipped"), voxelize(sphere_mesh({0, 0, 0}, 5), l, "sphere"));
}

TEST(Voxelize, DuplicateFacetsDoNotMatter) {
  TriangleMesh doubled = sphere_mesh({0, 0, 0}, 5);
  const std::size_t n = doubled.triangles.size();
  for (std::size_t i = 0; i < n; i += 7) doubled.triangles.push_back(doubled.triangles[i]);
  const Lattice l{0.5, {0, 0, 0}};
  EXPECT_EQ(voxelize(doubled, l, "doubled"), voxelize(sphere_mesh({0, 0, 0}, 5), l, "sphere"));
}

TEST(Voxelize, AnOpenMeshIsRefusedNotFilled) {
  TriangleMesh open = sphere_mesh({0, 0, 0}, 5);
  open.triangles.erase(open.triangles.begin() + 30);
  EXPECT_THROW(voxelize(open, {0.5, {0, 0, 0}}, "open"), InputError);
}

TEST(Voxelize, OpenVdbReferenceAgreesUpToBoundaryVoxels) {
  const TriangleMesh mesh = sphere_mesh({3, 4, 5}, 9, 32, 64);
  const Lattice l{0.5, {0, 0, 0}};
  const Solid exact = voxelize(mesh, l, "sphere", VoxelizeMethod::ExactScan);
  const Solid reference = voxelize(mesh, l, "sphere", VoxelizeMethod::OpenVdbLevelSet);
  const double differing = double(subtract(exact, reference).voxel_count() + subtract(reference, exact).voxel_count());
  EXPECT_GT(reference.voxel_count(), 0);
  EXPECT_LT(differing / double(exact.voxel_count()), 0.02);
}

TEST(Voxelize, ReportsProgressUpToOne) {
  double last = 0;
  int calls = 0;
  voxelize(sphere_mesh({0, 0, 0}, 5), {0.5, {0, 0, 0}}, "s", VoxelizeMethod::ExactScan, [&](double f) {
    EXPECT_GE(f, last);
    last = f;
    ++calls;
  });
  EXPECT_GT(calls, 1);
  EXPECT_DOUBLE_EQ(last, 1.0);
}

struct ExamplePart {
  const char* file;
};

class ExamplePartVolume : public ::testing::TestWithParam<ExamplePart> {};

// The accuracy bar: within 1.5% of the exact mesh volume at 0.5 mm and within
// 0.75% at 0.25 mm.
TEST_P(ExamplePartVolume, IsWithinToleranceOfTheMeshVolume) {
  const std::string path = std::string(HYBRIDCTL_SOURCE_DIR) + "/examples/parts/" + GetParam().file;
  const TriangleMesh mesh = read_stl(path);
  const double exact = signed_volume(clean_mesh(mesh));
  ASSERT_GT(exact, 0) << "mesh is not outward-oriented";
  for (auto [voxel, tolerance] : {std::pair{0.5, 0.015}, std::pair{0.25, 0.0075}}) {
    const double v = voxelize(mesh, {voxel, {0, 0, 0}}, path).volume();
    EXPECT_NEAR(v, exact, tolerance * exact) << path << " at " << voxel << " mm";
  }
}

INSTANTIATE_TEST_SUITE_P(Examples, ExamplePartVolume,
                         ::testing::Values(ExamplePart{"bracket.stl"}, ExamplePart{"thin-wall-slot.stl"},
                                           ExamplePart{"overhang.stl"}, ExamplePart{"fins.stl"},
                                           ExamplePart{"slots.stl"}, ExamplePart{"ribbed-pocket.stl"},
                                           ExamplePart{"flanged-hub.stl"}, ExamplePart{"flanged-hub-worn.stl"},
                                           ExamplePart{"channel-block.stl"}, ExamplePart{"arch-channel-block.stl"},
                                           ExamplePart{"boss-plate.stl"}, ExamplePart{"tube-plate.stl"},
                                           ExamplePart{"leaning-wall.stl"}, ExamplePart{"lidded-channel-block.stl"},
                                           ExamplePart{"bladed-disc.stl"}, ExamplePart{"gusset-bracket.stl"},
                                           ExamplePart{"rounded-box-dimple.stl"}, ExamplePart{"chamfered-cap.stl"}),
                         [](const auto& info) {
                           std::string name = info.param.file;
                           name = name.substr(0, name.find('.'));
                           for (char& c : name) if (c == '-') c = '_';
                           return name;
                         });

}  // namespace
}  // namespace hybridctl::geometry
