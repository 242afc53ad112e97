#pragma once
// The bead of an additive head and the T number that selects the head: the one
// definition the planner's primitives, the deposition generator, plan export and the
// material simulation use.
//
// A bead is the material one deposition pass lays down: an ellipsoid or a cylinder about
// +Z. Its programmed point is the bead's BOTTOM on its axis: the bead occupies z in
// [programmed z, programmed z + height]; an ellipsoid bead's centre is at programmed
// z + height / 2 (semi-axes width/2, width/2, height/2). A deposition toolpath therefore
// programs the surface the bead is laid on.

#include <cstddef>
#include <vector>

#include "config/machine.hpp"
#include "geometry/morphology.hpp"

namespace hybridctl::instruments {

struct Bead {
  config::BeadShape shape = config::BeadShape::Ellipsoid;
  double width = 0;   // mm, the bead's diameter across the path
  double height = 0;  // mm, along +Z
  // Optional non-cutting body (nozzle) above the programmed point, sections in mm along
  // +Z, checked like a cutter's body.
  std::vector<geometry::AxialSection> body;
  // What the head builds without support (instruments/support_rule.hpp); bead_of copies
  // the head's. A hand-built bead has no overhang and no bridge: only straight stacks.
  config::SupportLimits support;
};

// The bead of a head: its shape, width and height, its nozzle body (a cylinder of the
// nozzle's diameter over [standoff, standoff + length]; none without a nozzle) and its
// support limits.
Bead bead_of(const config::AdditiveHead& head);

// The bead's half-width (mm) at `dz` above its programmed point (its bottom), as the
// material simulation lays it (docs/simulation.md): an ellipsoid bead is as wide as its
// widest line from its bottom up to its middle (molten metal wets what it is laid on) and
// narrows as the ellipse above; a cylinder is as wide all the way up. 0 outside [0, height].
// What a pass lays at a voxel centre that height above the layer's bottom reaches this far
// sideways, and no farther.
double bead_half_width_at(const Bead& bead, double dz);

// How far (mm) a wall of beads laid `layer_height` apart stands in between its layers from
// where it stands out, as the material simulation lays them: each bead is full width up to
// its middle and narrows above it, under the next layer's bottom. A cylinder's wall is
// flat (0) unless the layers stand apart (then its whole half-width).
double bead_wall_scallop(const Bead& bead, double layer_height);

// How far under the crests (mm) two tracks laid side by side `spacing` apart meet on top:
// an ellipsoid track's top is the upper half of its ellipse, a cylinder's is flat (0).
double bead_top_dip(const Bead& bead, double spacing);

// The T number that selects a head: its tool_number when positive (the machine loader
// always sets one), otherwise `fallback`.
int head_tool_number(const config::AdditiveHead& head, int fallback);
// The T number that selects machine.heads[head_index]: its tool_number when positive,
// otherwise the machine file's default, config::kDefaultHeadToolNumberBase (100) + the
// index. Plan export and the simulated machine both number heads by it.
int head_tool_number(const config::Machine& machine, std::size_t head_index);

}  // namespace hybridctl::instruments
