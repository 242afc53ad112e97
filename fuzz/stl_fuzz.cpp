// Fuzz target: the STL reader (geometry/mesh.hpp: parse_stl, the in-memory form of
// read_stl) on arbitrary bytes, binary or ASCII, then what `hybridctl inspect` does with a
// mesh: cleaning, the edge census, the closedness check, volume and bounds.
// Contract: parse_stl and require_closed throw hybridctl::InputError (and nothing else)
// with the file name in the message.

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "common/error.hpp"
#include "fuzz/fuzz_check.hpp"
#include "geometry/mesh.hpp"

namespace geometry = hybridctl::geometry;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  const std::string name = "fuzz.stl";
  geometry::TriangleMesh mesh;
  try {
    (void)geometry::detect_stl_format(bytes);
    mesh = geometry::parse_stl(bytes, name);
  } catch (const hybridctl::InputError& e) {
    FUZZ_CHECK(std::string_view(e.what()).starts_with(name), "an STL error names the file");
    return 0;
  }
  FUZZ_CHECK(!mesh.triangles.empty(), "a mesh read without error has triangles");
  geometry::MeshReport report;
  const geometry::TriangleMesh cleaned = geometry::clean_mesh(mesh, &report);
  FUZZ_CHECK(report.triangles == mesh.triangles.size(), "the report counts the triangles read");
  FUZZ_CHECK(cleaned.triangles.size() + report.duplicate_facets + report.degenerate_facets == mesh.triangles.size(),
             "cleaning removes exactly the duplicate and degenerate facets it reports");
  // STL has no welding tolerance: identical coordinates are one vertex, and -0 is 0 (as
  // exporters write either). Writing every -0 as +0 changes nothing.
  geometry::TriangleMesh positive = mesh;
  for (auto& t : positive.triangles)
    for (auto& v : t) v = {v.x + 0.0, v.y + 0.0, v.z + 0.0};
  geometry::MeshReport positive_report;
  (void)geometry::clean_mesh(positive, &positive_report);
  FUZZ_CHECK(positive_report.boundary_edges == report.boundary_edges &&
                 positive_report.nonmanifold_edges == report.nonmanifold_edges &&
                 positive_report.duplicate_facets == report.duplicate_facets &&
                 positive_report.degenerate_facets == report.degenerate_facets,
             "the edge census does not depend on the sign of zero");
  try {
    geometry::require_closed(report, name);
  } catch (const hybridctl::InputError&) {
    FUZZ_CHECK(!report.closed(), "only an open mesh is refused");
  }
  (void)geometry::signed_volume(cleaned);
  (void)geometry::bounds(mesh);
  return 0;
}
