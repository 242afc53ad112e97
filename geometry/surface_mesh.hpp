#pragma once
// A triangle mesh of a solid's surface, for viewing and for STL export.

#include "geometry/mesh.hpp"
#include "geometry/solid.hpp"

namespace hybridctl::geometry {

// OpenVDB's volume-to-mesh on a level set built from the solid's voxels: a closed,
// smooth-looking surface through the voxel faces' midpoints. `adaptivity` in [0, 1]
// merges flat regions into larger polygons (0: none).
TriangleMesh surface_mesh(const Solid& solid, double adaptivity = 0.0);

}  // namespace hybridctl::geometry
