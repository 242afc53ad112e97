// Export: .vdb round trips exactly (lattice included), the surface mesh is closed and
// encloses about the voxel volume, PNG slices are one per layer.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "common/error.hpp"
#include "geometry/png_slices.hpp"
#include "geometry/shapes.hpp"
#include "geometry/surface_mesh.hpp"
#include "geometry/vdb_file.hpp"
#include "geometry/voxelize.hpp"

namespace hybridctl::geometry {
namespace {

class TempDir {
 public:
  TempDir() : path_(std::filesystem::temp_directory_path() / ("hybridctl-test-" + std::to_string(::getpid()) + "-" +
                                                               ::testing::UnitTest::GetInstance()->current_test_info()->name())) {
    std::filesystem::create_directories(path_);
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

const Lattice kOffsetLattice{0.25, {-1.5, 2.0, 0.75}};

Solid sample_solid() {
  return subtract(make_box(kOffsetLattice, {{-5, -3, 0}, {12, 6, 7}}),
                  make_cylinder(kOffsetLattice, Axis::Z, {3, 1, -1}, 2.5, 10));
}

TEST(VdbFile, RoundTripsVoxelsAndLattice) {
  TempDir dir;
  const Solid s = sample_solid();
  write_vdb(s, dir / "s.vdb");
  const Solid back = read_vdb(dir / "s.vdb");
  EXPECT_DOUBLE_EQ(back.voxel_size(), 0.25);
  EXPECT_NEAR(back.lattice().origin.x, -1.5, 1e-9);
  EXPECT_NEAR(back.lattice().origin.y, 2.0, 1e-9);
  EXPECT_NEAR(back.lattice().origin.z, 0.75, 1e-9);
  // Same lattice up to rounding of the stored transform: compare voxel by voxel.
  ASSERT_EQ(back.voxel_count(), s.voxel_count());
  EXPECT_EQ(back.bounding_box(), s.bounding_box());
  s.for_each_voxel([&](Index3 v) { ASSERT_TRUE(back.contains(v)); });
}

TEST(VdbFile, BadFilesAreRefusedWithTheirName) {
  TempDir dir;
  std::ofstream(dir / "junk.vdb") << "this is not a vdb file";
  try {
    read_vdb(dir / "junk.vdb");
    FAIL() << "junk accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("junk.vdb"), std::string::npos) << e.what();
  }
  EXPECT_THROW(read_vdb(dir / "missing.vdb"), InputError);
}

TEST(VdbFile, NoHalfWrittenFileIsLeftWhenTheDirectoryIsMissing) {
  TempDir dir;
  EXPECT_THROW(write_vdb(sample_solid(), dir / "no" / "such" / "dir.vdb"), InputError);
  EXPECT_FALSE(std::filesystem::exists(dir / "no"));
}

TEST(SurfaceMesh, IsClosedOutwardAndEnclosesTheVoxels) {
  const Solid s = sample_solid();
  const TriangleMesh mesh = surface_mesh(s);
  MeshReport report;
  clean_mesh(mesh, &report);
  EXPECT_TRUE(report.closed()) << report.boundary_edges << " boundary edges";
  const double v = signed_volume(mesh);
  EXPECT_GT(v, 0) << "surface faces inward";
  EXPECT_NEAR(v, s.volume(), 0.05 * s.volume());
  // Voxelizing the surface again on the same lattice gives nearly the same solid.
  const Solid again = voxelize(mesh, s.lattice(), "surface");
  const double differing = double(subtract(s, again).voxel_count() + subtract(again, s).voxel_count());
  EXPECT_LT(differing / double(s.voxel_count()), 0.05);
}

TEST(PngSlices, WritesOnePngPerLayer) {
  TempDir dir;
  const Solid s = make_box({1.0, {0, 0, 0}}, {{0, 0, 0}, {10, 5, 3}});
  const auto files = write_png_slices(s, dir / "slices", 100);
  ASSERT_EQ(files.size(), 3u);
  for (const auto& f : files) {
    std::ifstream in(f, std::ios::binary);
    char header[24] = {};
    in.read(header, sizeof header);
    EXPECT_EQ(std::string(header + 1, 3), "PNG");
    const auto be32 = [&](int at) {
      return (unsigned char)header[at] << 24 | (unsigned char)header[at + 1] << 16 | (unsigned char)header[at + 2] << 8 |
             (unsigned char)header[at + 3];
    };
    EXPECT_EQ(be32(16), 100);  // 10 voxels scaled 10x
    EXPECT_EQ(be32(20), 50);
  }
}

}  // namespace
}  // namespace hybridctl::geometry
