#pragma once
// Meshes for the report: a voxel solid's surface by the project's meshing
// (geometry::surface_mesh, OpenVDB's volume-to-mesh), kept within a triangle budget by
// meshing a coarser copy of the solid, as indexed triangles with shared vertices, and
// their compact encoding for the page (docs/report.md, "Meshes and budgets").

#include <cstdint>
#include <string>
#include <vector>

#include "geometry/mesh.hpp"
#include "geometry/solid.hpp"

namespace hybridctl::report {

struct IndexedMesh {
  std::vector<float> positions;   // x, y, z per vertex, mm, part frame
  std::vector<std::uint32_t> indices;  // three per triangle, outward winding
  double voxel_size = 0;          // of the solid that was meshed (coarser when decimated)
  std::size_t triangles() const { return indices.size() / 3; }
  bool empty() const { return indices.empty(); }
};

// The solid with voxels `factor` times larger on the same origin: a coarse voxel is
// occupied when at least half of the fine voxels it covers are.
geometry::Solid coarsen(const geometry::Solid& solid, int factor);

// The surface of `solid` in at most `triangle_budget` triangles: meshed as it is when it
// fits, else on the coarsest of 2x, 3x, 4x, ... voxels needed (up to 16x, then the
// budget is exceeded rather than the shape lost). Adjacent flat faces are merged
// (OpenVDB's adaptivity).
IndexedMesh budget_mesh(const geometry::Solid& solid, std::size_t triangle_budget);

// A triangle mesh as it is (no meshing, no budget: the design's own STL), its vertices
// shared where they are equal, its triangles in the same order.
IndexedMesh indexed_mesh(const geometry::TriangleMesh& mesh, double voxel_size = 0);

// Base64 of raw little-endian bytes (what the page decodes into typed arrays).
std::string base64(const void* data, std::size_t bytes);

}  // namespace hybridctl::report
