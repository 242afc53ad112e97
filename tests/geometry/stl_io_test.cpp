// STL import: both encodings read; every kind of bad file is refused with a message
// that says where and what was expected; closedness is checked, never assumed.

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

#include "common/error.hpp"
#include "geometry/mesh.hpp"
#include "mesh_fixtures.hpp"

namespace hybridctl::geometry {
namespace {

using testing::box_mesh;

std::string binary_stl(const TriangleMesh& mesh) {
  std::string bytes(80, ' ');
  std::memcpy(bytes.data(), "solid but binary", 16);  // as some exporters write it
  const std::uint32_t n = std::uint32_t(mesh.triangles.size());
  bytes.append(reinterpret_cast<const char*>(&n), 4);
  for (const Triangle& t : mesh.triangles) {
    float rec[12] = {0, 0, 0};
    for (int v = 0; v < 3; ++v) {
      rec[3 + 3 * v] = float(t[v].x);
      rec[4 + 3 * v] = float(t[v].y);
      rec[5 + 3 * v] = float(t[v].z);
    }
    bytes.append(reinterpret_cast<const char*>(rec), sizeof rec);
    bytes.append(2, '\0');
  }
  return bytes;
}

std::string ascii_stl(const TriangleMesh& mesh) {
  std::string s = "solid cube\n";
  for (const Triangle& t : mesh.triangles) {
    s += "  facet normal 0 0 0\n    outer loop\n";
    for (const Vec3& v : t) s += "      vertex " + std::to_string(v.x) + " " + std::to_string(v.y) + " " + std::to_string(v.z) + "\n";
    s += "    endloop\n  endfacet\n";
  }
  return s + "endsolid cube\n";
}

std::string error_of(std::string_view bytes) {
  try {
    parse_stl(bytes, "part.stl");
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

const TriangleMesh kCube = box_mesh({0, 0, 0}, {10, 20, 30});

TEST(StlRead, BinaryAndAsciiGiveTheSameTriangles) {
  const TriangleMesh from_binary = parse_stl(binary_stl(kCube), "b.stl");
  const TriangleMesh from_ascii = parse_stl(ascii_stl(kCube), "a.stl");
  ASSERT_EQ(from_binary.triangles.size(), 12u);
  ASSERT_EQ(from_ascii.triangles.size(), 12u);
  EXPECT_EQ(from_binary.triangles, from_ascii.triangles);
  EXPECT_DOUBLE_EQ(signed_volume(from_binary), 6000.0);
}

TEST(StlRead, ABinaryHeaderStartingWithSolidIsStillBinary) {
  EXPECT_EQ(detect_stl_format(binary_stl(kCube)), StlFormat::Binary);
  EXPECT_EQ(detect_stl_format(ascii_stl(kCube)), StlFormat::Ascii);
}

TEST(StlRead, WriteThenReadRoundTrips) {
  const auto path = std::filesystem::temp_directory_path() / "hybridctl-roundtrip.stl";
  write_stl(kCube, path);
  EXPECT_EQ(read_stl(path).triangles, kCube.triangles);
  std::filesystem::remove(path);
}

TEST(StlRead, AnEmptyFileIsRefused) {
  EXPECT_NE(error_of("").find("part.stl: empty file"), std::string::npos) << error_of("");
}

TEST(StlRead, AFileShorterThanTheBinaryHeaderIsTruncated) {
  const std::string e = error_of(std::string(40, '\x01'));
  EXPECT_NE(e.find("truncated: 40 bytes"), std::string::npos) << e;
}

TEST(StlRead, ABinaryFileShorterThanItsTriangleCountSaysIsTruncated) {
  std::string bytes = binary_stl(kCube);
  bytes.resize(bytes.size() - 30);
  const std::string e = error_of(bytes);
  EXPECT_NE(e.find("truncated"), std::string::npos) << e;
  EXPECT_NE(e.find("announces 12 triangles"), std::string::npos) << e;
  EXPECT_NE(e.find("684 bytes"), std::string::npos) << e;  // 84 + 12 * 50
}

TEST(StlRead, ABinaryFileLongerThanItsTriangleCountSaysIsAMismatch) {
  std::string bytes = binary_stl(kCube) + std::string(50, '\0');
  const std::string e = error_of(bytes);
  EXPECT_NE(e.find("size mismatch"), std::string::npos) << e;
  EXPECT_NE(e.find("734 bytes"), std::string::npos) << e;
}

TEST(StlRead, ABinaryFileWithZeroTrianglesIsEmpty) {
  std::string bytes(84, '\0');
  EXPECT_NE(error_of(bytes).find("holds no triangles"), std::string::npos) << error_of(bytes);
}

TEST(StlRead, ANonFiniteCoordinateIsRefusedWithItsTriangle) {
  TriangleMesh bad = kCube;
  bad.triangles[4][1].y = std::nan("");
  const std::string e = error_of(binary_stl(bad));
  EXPECT_NE(e.find("triangle 5 vertex 2 has a non-finite coordinate"), std::string::npos) << e;

  std::string text = ascii_stl(kCube);
  text.replace(text.find("vertex ") + 7, 8, "nan     ");
  const std::string a = error_of(text);
  EXPECT_NE(a.find("part.stl:4:"), std::string::npos) << a;
  EXPECT_NE(a.find("non-finite"), std::string::npos) << a;
}

TEST(StlRead, RandomBytesAreRefusedNotCrashedOn) {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 50; ++trial) {
    std::string bytes(std::size_t(rng() % 2000), '\0');
    for (char& c : bytes) c = char(rng());
    if (trial % 5 == 0) bytes.replace(0, std::min<std::size_t>(5, bytes.size()), "solid");
    EXPECT_THROW(parse_stl(bytes, "junk.stl"), InputError);
  }
}

TEST(StlRead, AsciiErrorsNameLineAndColumnAndWhatWasExpected) {
  const std::string e = error_of("solid x\n  facet normal 0 0 1\n    outer loop\n      vertex 1 2 3\n      vertex 1 2 oops\n");
  EXPECT_NE(e.find("part.stl:5:18: expected a vertex coordinate in mm, got 'oops'"), std::string::npos) << e;
  const std::string f = error_of("solid x\n  facet normal 0 0 1\n    outer hoop\n");
  EXPECT_NE(f.find("part.stl:3:11: expected 'loop', got 'hoop'"), std::string::npos) << f;
}

TEST(StlRead, ATruncatedAsciiFileSaysWhatItWasStillWaitingFor) {
  std::string text = ascii_stl(kCube);
  text.resize(text.size() / 2);
  text.resize(text.rfind("vertex") + 6);
  const std::string e = error_of(text);
  EXPECT_NE(e.find("unexpected end of file"), std::string::npos) << e;
  EXPECT_NE(e.find("expected a vertex coordinate"), std::string::npos) << e;
}

TEST(StlRead, AMissingFileSaysSo) {
  EXPECT_THROW(read_stl("/nonexistent/part.stl"), InputError);
}

TEST(MeshCheck, DuplicateAndReversedFacetsAreRemovedAndTheMeshStaysClosed) {
  TriangleMesh messy = kCube;
  messy.triangles.push_back(kCube.triangles[3]);
  messy.triangles.push_back({kCube.triangles[7][2], kCube.triangles[7][1], kCube.triangles[7][0]});
  messy.triangles.push_back({Vec3{1, 1, 1}, Vec3{1, 1, 1}, Vec3{2, 2, 2}});
  MeshReport report;
  const TriangleMesh clean = clean_mesh(messy, &report);
  EXPECT_EQ(report.duplicate_facets, 2u);
  EXPECT_EQ(report.degenerate_facets, 1u);
  EXPECT_TRUE(report.closed());
  EXPECT_EQ(clean.triangles.size(), 12u);
}

TEST(MeshCheck, AnOpenMeshIsReportedWithItsBoundaryEdgeCount) {
  TriangleMesh open = kCube;
  open.triangles.pop_back();  // one facet missing: its three edges are boundary
  MeshReport report;
  clean_mesh(open, &report);
  EXPECT_FALSE(report.closed());
  EXPECT_EQ(report.boundary_edges, 3u);
  try {
    require_closed(report, "open.stl");
    FAIL() << "an open mesh was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("open.stl: open mesh: 3 boundary edges"), std::string::npos) << e.what();
  }
}

TEST(MeshCheck, MinusZeroIsTheSameVertexAsZero) {
  // Found by fuzz/stl_fuzz (fuzz/corpus/stl/regression-minus-zero.stl): exporters write -0
  // for 0 now and then; welding hashed the bits of the coordinates, so -0 and 0 (equal as
  // numbers) were two vertices and a closed mesh counted as open.
  TriangleMesh signed_zeros = box_mesh({0, 0, 0}, {10, 10, 10});
  for (std::size_t i = 0; i < signed_zeros.triangles.size(); i += 2)
    for (Vec3& v : signed_zeros.triangles[i])
      for (double* c : {&v.x, &v.y, &v.z})
        if (*c == 0) *c = -0.0;
  for (const TriangleMesh& mesh : {signed_zeros, parse_stl(binary_stl(signed_zeros), "zeros.stl"),
                                   parse_stl(ascii_stl(signed_zeros), "zeros.stl")}) {
    MeshReport report;
    clean_mesh(mesh, &report);
    EXPECT_TRUE(report.closed()) << report.boundary_edges << " boundary edges";
    EXPECT_EQ(report.nonmanifold_edges, 0u);
    EXPECT_NO_THROW(require_closed(report, "zeros.stl"));
  }
}

}  // namespace
}  // namespace hybridctl::geometry
