#pragma once
// What material already present keeps a head from depositing an atom. A head deposits
// from its setup's approach side, layer on layer towards itself; a voxel with material
// above it (towards the head) in its column cannot be reached: the toolpath skips that
// part of the layer (toolpaths/deposition_path.cpp, "layer_skipped") and validation
// rejects the plan. The search uses this relation to leave such actions out, so that it
// does not offer validation plans that can only fail (e.g. deposit from +Z, turn the part
// over, deposit from -Z under what is there).

#include <vector>

#include "geometry/morphology.hpp"
#include "planner/problem/atom_set.hpp"
#include "planner/atoms/atoms.hpp"
#include "planner/search/search.hpp"

namespace hybridctl::planner {

// For each atom b, the atoms a with a voxel `gap` or more voxels above a voxel of b in one
// column along `approach` (above: towards the approach side). With the gap of
// deposit_reach_gap, material that may lie in the same layer as b, which the toolpath
// still reaches, stays out of the relation. Atoms with nothing above them get an empty set (no words).
std::vector<AtomSet> atoms_above(const AtomDecomposition& atoms, geometry::AxisDirection approach, int gap);

// The nozzle body a head carries over the point it deposits at: a cylinder of `radius`
// from `standoff` to `standoff + length` above it (instruments/bead.hpp), in voxels.
struct NozzleReach {
  double radius = 0;
  int standoff = 0, length = 0;
};

// For each atom b, the atoms a with a voxel inside the nozzle body placed over some voxel
// of b: present, they meet the nozzle when the head deposits b (the simulator's
// body_collision). The body is taken as the square inscribed in its circle (never more
// than the nozzle), and `a` counts when its highest voxel near the column lies between the
// stand-off over b's lowest voxel there and the body's top over b's highest (an atom that
// reaches above the body's top may pass over it: not counted).
std::vector<AtomSet> atoms_in_nozzle_reach(const AtomDecomposition& atoms, geometry::AxisDirection approach,
                                           const NozzleReach& nozzle);

// What may carry the first layer of `region` built along `approach` (its lowest voxel
// layer along the build direction, which a build plate carries when the plan starts with
// it): per atom holding a voxel of that layer, OnPlate when one of them lies on the
// domain's lowest layer (where the simulated machine's plate is), else NeedsCarrier with
// every atom within `reach` voxels across and up to two layers under (or in) that layer.
// `reach` should cover a bead's half width, the head's cone and a voxel of slack: an atom
// of the first layer with none of those present has nothing under or beside it at all.
DepositFooting deposit_footing(const AtomDecomposition& atoms, const geometry::Solid& region,
                               geometry::AxisDirection approach, int reach);

// The gap for a head's layer height on a lattice of voxel size h: floor(layer / h) + 1.
int deposit_reach_gap(double layer_height, double voxel_size);

}  // namespace hybridctl::planner
