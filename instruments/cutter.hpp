#pragma once
// The cutter of a cutting tool: the one definition the planner's primitives, the pocket
// generator and the material simulation are all built from.
//
// A cutter is a cutting part and a non-cutting body (shank, holder), both bodies of
// revolution, given as geometry::AxialSection profiles in mm along +Z from the tool TIP
// (the lowest point of the cutting part on its axis: a ball mill's tip, not its ball
// centre):
//
//   flat   a cylinder of the tool's radius over [0, flute_length]
//   ball   a hemisphere (centre at the radius) over [0, r], then a cylinder up to the flute length
//   bull   a torus corner (tube corner_radius, ring r - corner_radius) over [0, corner_radius],
//          then a cylinder up to the flute length
//   body   the shank over [flute, flute + shank.length], then the holder from there on,
//          which never ends: above it is the spindle, so whatever lies in its shadow is
//          out of reach.

#include <vector>

#include "config/machine.hpp"
#include "geometry/morphology.hpp"

namespace hybridctl::instruments {

// The machine file's documented defaults (docs/machine-file.md) for the values a tool
// built by hand leaves at 0: flute 3 x diameter, shank {diameter, 2 x diameter}, holder
// {50, 60}, step_down 0.5 x diameter, step_over 0.4 x diameter, feed 1000, plunge_feed
// 300; a ball's corner radius is half its diameter, a flat's 0. The machine loader sets
// all of them, so a loaded tool comes back as it is. Throws std::invalid_argument
// naming the tool for one without a diameter, or a bull-nose tool without
// 0 < corner_radius < diameter/2.
config::CuttingTool with_defaults(config::CuttingTool tool);

struct Cutter {
  std::vector<geometry::AxialSection> cutting;  // removes material
  std::vector<geometry::AxialSection> body;     // must not touch material (shank, holder)

  // Cutting part and body as one profile: the whole tool.
  std::vector<geometry::AxialSection> whole() const;
};

// The cutter of `tool`, its defaults applied (with_defaults).
Cutter cutter_of(const config::CuttingTool& tool);

// The radius of a profile (a union of sections) at `z` mm along its axis, squared;
// negative where no section reaches.
double radius_squared_at(const std::vector<geometry::AxialSection>& profile, double z);

}  // namespace hybridctl::instruments
