#pragma once
// The instruments the material simulation sweeps along moves, in the work frame (the
// setup's frame, +Z = the spindle axis pointing away from the part):
//
//  - a Cutter: a cutting part and a non-cutting body (shank, holder), both bodies of
//    revolution about +Z. The programmed point is the tool TIP: the lowest point of
//    the cutting part on its axis (a ball mill's tip, not its ball centre).
//  - a Bead: the material one deposition pass lays down, an ellipsoid or a cylinder
//    about +Z. The programmed point is the bead's BOTTOM on its axis: the bead occupies
//    z in [programmed z, programmed z + height]; an ellipsoid bead's centre is at
//    programmed z + height / 2. A deposition toolpath therefore programs the surface the
//    bead is laid on.
//
// Sections are geometry::AxialSection values measured in mm along +Z from the
// programmed point, as the planner's structuring elements are (planner/machine_primitives).

#include <vector>

#include "config/machine.hpp"
#include "geometry/morphology.hpp"

namespace hybridctl::sim {

struct Cutter {
  std::vector<geometry::AxialSection> cutting;  // removes material
  std::vector<geometry::AxialSection> body;     // must not touch material (shank, holder)
};

struct Bead {
  config::BeadShape shape = config::BeadShape::Ellipsoid;
  double width = 0;   // mm, the bead's diameter across the path
  double height = 0;  // mm, along +Z
  // Optional non-cutting body (nozzle) above the programmed point, checked like a
  // cutter's body; bead_of leaves it empty (the machine file gives no nozzle standoff).
  std::vector<geometry::AxialSection> body;
};

// The cutter of a tool: flat (cylinder), ball (hemisphere + cylinder) or bull (torus
// corner + cylinder) over the flute length; then the shank; then the holder, which never
// ends (above it the spindle): the same shapes the planner derives its primitives from.
Cutter cutter_of(const config::CuttingTool& tool);

// The bead of a head: its shape, width and height, with no body.
Bead bead_of(const config::AdditiveHead& head);

}  // namespace hybridctl::sim
