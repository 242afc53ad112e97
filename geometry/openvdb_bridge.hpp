#pragma once
// Conversions between Solid and OpenVDB grids. Include only from geometry/ .cpp files:
// OpenVDB headers are heavy and stay out of every other translation unit.

#include <openvdb/openvdb.h>

#include "geometry/solid.hpp"

namespace hybridctl::geometry::vdb {

// Registers OpenVDB's types once per process.
void initialize();
// Index (i,j,k) of the grid is voxel (i,j,k) of the lattice: cell-centred transform.
openvdb::math::Transform::Ptr transform_of(const Lattice& lattice);
openvdb::BoolGrid::Ptr to_bool_grid(const Solid& solid);
// Occupied voxels of any active topology (value true / > 0.5 for fog volumes).
Solid from_active_voxels(const openvdb::BoolGrid& grid, const Lattice& lattice);

}  // namespace hybridctl::geometry::vdb
