#pragma once
// Triangle meshes as they come from STL files, and the checks that decide whether a
// mesh bounds a solid: closedness (every edge shared by an even number of facets),
// with duplicate facets and facets repeated with the opposite winding removed first.

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "geometry/solid.hpp"

namespace hybridctl::geometry {

using Triangle = std::array<Vec3, 3>;

struct TriangleMesh {
  std::vector<Triangle> triangles;
  friend bool operator==(const TriangleMesh&, const TriangleMesh&) = default;
};

enum class StlFormat { Binary, Ascii };

// Reads a binary or ASCII STL file. Throws hybridctl::InputError naming the file, and
// the byte offset or line:column, for an empty, truncated, garbage or NaN-bearing file,
// or a binary file whose triangle count disagrees with its size.
TriangleMesh read_stl(const std::filesystem::path& path);
// The same from bytes in memory; `name` is used in messages.
TriangleMesh parse_stl(std::string_view bytes, const std::string& name);
StlFormat detect_stl_format(std::string_view bytes);

// Writes a binary STL (temporary file, then rename).
void write_stl(const TriangleMesh& mesh, const std::filesystem::path& path);

struct MeshReport {
  std::size_t triangles = 0;             // as read
  std::size_t duplicate_facets = 0;      // removed: same three vertices, either winding
  std::size_t degenerate_facets = 0;     // removed: a vertex repeated
  std::size_t boundary_edges = 0;        // edges used by an odd number of facets
  std::size_t nonmanifold_edges = 0;     // edges used by more than two facets
  std::array<Vec3, 2> first_boundary_edge{};
  bool closed() const { return boundary_edges == 0; }
};

// Removes duplicate and degenerate facets; reports what it removed and the edge census.
TriangleMesh clean_mesh(const TriangleMesh& mesh, MeshReport* report = nullptr);
// Throws hybridctl::InputError, naming `name` and the count of boundary edges, if the
// (cleaned) mesh is open. An open mesh does not bound a solid and is never filled.
void require_closed(const MeshReport& report, const std::string& name);

// Volume by signed tetrahedra; positive for an outward-oriented closed mesh.
double signed_volume(const TriangleMesh& mesh);
Box3 bounds(const TriangleMesh& mesh);

// The facets that lie square to an axis (their three vertices share one coordinate), wound
// so that their normals point out of the solid whatever the mesh's winding: the flat faces
// a setup's floors and walls are made to exactly (toolpaths/pocket_path.hpp).
std::vector<Triangle> axis_square_faces(const TriangleMesh& mesh);

}  // namespace hybridctl::geometry
