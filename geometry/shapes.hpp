#pragma once
// Analytic solids voxelized on a lattice: a voxel belongs to the shape when its centre
// does (boundaries half-open along X so that boxes tile without overlap).

#include "geometry/solid.hpp"

namespace hybridctl::geometry {

Solid make_box(const Lattice& lattice, const Box3& box);
Solid make_sphere(const Lattice& lattice, Vec3 centre, double radius);
Solid make_ellipsoid(const Lattice& lattice, Vec3 centre, Vec3 radii);
// A right circular cylinder along `axis`, from `base_centre` over `length` mm in the
// positive axis direction.
Solid make_cylinder(const Lattice& lattice, Axis axis, Vec3 base_centre, double radius, double length);

}  // namespace hybridctl::geometry
