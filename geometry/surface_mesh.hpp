#pragma once
// A triangle mesh of a solid's surface, for viewing and for STL export.

#include "geometry/mesh.hpp"
#include "geometry/solid.hpp"

namespace hybridctl::geometry {

// How the surface is extracted (both by OpenVDB's volume-to-mesh).
enum class SurfaceMethod {
  LevelSet,   // from a narrow-band level set built from the voxels: smooth-looking
  Occupancy,  // from the occupancy itself (1 inside, 0 outside, at 0.5): chamfered voxel
              // faces, several times faster (no level set to build); for previews
};

// A closed surface through the voxel faces' midpoints. `adaptivity` in [0, 1] merges flat
// regions into larger polygons (0: none).
TriangleMesh surface_mesh(const Solid& solid, double adaptivity = 0.0,
                          SurfaceMethod method = SurfaceMethod::LevelSet);

}  // namespace hybridctl::geometry
