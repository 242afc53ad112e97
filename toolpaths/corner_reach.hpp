#pragma once
// Inside corners of the design that no cutter of the machine comes near (docs/toolpaths.md,
// "Inside corners no cutter reaches"): the vertical edges where two walls of the STL meet
// with air between them at less than a straight angle, and, along each, the stretch where
// no tool of the machine, from any setup's direction, gets its cutting part within
// `reach` of the edge while every part of it (flutes, shank, holder) stays out of the
// design, as every toolpath of hybridctl keeps it (toolpaths.md: no move puts a cutter
// into the STL's solid).
//
//   CornerReachOptions o;
//   o.reach = tolerance;
//   for (const UnreachedCorner& c : corners_no_cutter_reaches(triangles, machine, o)) ...
//
// A lower bound, found in the plane: at each height tried, around each corner, the design
// within a window where all its facets are vertical (over the heights a tool near the
// corner spans) is a prism, so a tool stands clear of it exactly when its widest section
// there stands clear of the prism's cross-section. A tool along Z is a disc there (its
// narrowest part's radius: any height of the window may hold the shank or the holder
// instead of the flutes); a tool along X or Y is seen from above: the union of its
// flutes', shank's and holder's outlines along its axis. The tip positions whose section
// meets the cross-section (shrunk by `allowance`) are the tool's blocked region, a
// Minkowski sum (Clipper); the corner is as far from the tool as the tip positions that
// put the corner inside the cutting part lie from the free ones. Every approximation
// leans towards the tool: the window and the shrunk section hold less design than the
// STL, the round outlines that block are inscribed polygons and the one that reaches is
// circumscribed. So "unreached" is proven for the corners it names; corners it cannot
// judge (a facet that is not vertical too near) are not named.

#include <string>
#include <vector>

#include "config/machine.hpp"
#include "geometry/mesh.hpp"
#include "plan/unreached_corner.hpp"

namespace hybridctl::toolpaths {

struct CornerReachOptions {
  double reach = 0.3;             // mm: a corner no cutting part comes within this of is unreached
  double allowance = 0.005;       // mm: how far into the design a tool may stand (more than the keep-out's rounding)
  double step = 0.2;              // mm between the heights tried
  double max_air_angle = 165;     // degrees: flatter corners (a faceted bore) are not tried
  double max_window = 25;         // mm: how far round a corner the design is taken in
  double min_stretch = 0;         // mm: shorter unreached stretches are not named
  std::size_t max_corners = 16;   // corners are tried until this many stretches are named
  double chord_tolerance = 0.001; // mm: the polygons' chords against their arcs
};

// The stretches of `design`'s vertical inside edges where no tool of `machine`, from the
// approach of any of its setups, comes within options.reach, at least options.min_stretch
// long, lowest edge first: corners are tried in the order of their places until
// options.max_corners stretches are named, the others left untried. `design` is a closed mesh (geometry::clean_mesh), part frame.
std::vector<plan::UnreachedCorner> corners_no_cutter_reaches(const std::vector<geometry::Triangle>& design,
                                                             const config::Machine& machine,
                                                             const CornerReachOptions& options);

}  // namespace hybridctl::toolpaths
