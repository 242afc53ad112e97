#pragma once
// Turning a closed triangle mesh into a voxel solid: a voxel belongs to the solid when
// its centre is inside the mesh.

#include <functional>

#include "geometry/mesh.hpp"
#include "geometry/solid.hpp"

namespace hybridctl::geometry {

enum class VoxelizeMethod {
  // Exact scan conversion: even-odd crossings of rays along X through every row of
  // voxel centres, with a tie rule that counts a ray through a shared edge or vertex
  // exactly once. Independent of facet orientation. The default (see
  // docs/design/solid-storage.md for the measurements).
  ExactScan,
  // OpenVDB's mesh-to-level-set conversion, interior taken where the distance is
  // negative. Kept as an independent reference and baseline.
  OpenVdbLevelSet,
};

// Called with the fraction done, 0..1, from any thread, never concurrently.
using ProgressFn = std::function<void(double)>;

// Voxelizes a mesh on `lattice`. The mesh is cleaned first (duplicate and degenerate
// facets removed); an open mesh is refused with hybridctl::InputError naming `name`.
Solid voxelize(const TriangleMesh& mesh, const Lattice& lattice, const std::string& name,
               VoxelizeMethod method = VoxelizeMethod::ExactScan, const ProgressFn& progress = {});

// Only for meshes already cleaned and known closed.
Solid voxelize_exact_scan(const TriangleMesh& mesh, const Lattice& lattice, const ProgressFn& progress = {});
Solid voxelize_openvdb(const TriangleMesh& mesh, const Lattice& lattice);

}  // namespace hybridctl::geometry
