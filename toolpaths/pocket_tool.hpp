#pragma once
// The pocket generator's tool on the lattice (internal to toolpaths/pocket_*.cpp): the
// cutter of instruments/cutter.hpp, tip at the origin, axis +Z (work frame), with what
// the generator derives from it once per voxel size: the conservative guards
// (instruments/elements.hpp), the cutter and the body as discs per level above the tip,
// and for every column around the axis the lowest height the tool reaches there.

#include <limits>
#include <utility>
#include <vector>

#include "geometry/morphology.hpp"
#include "instruments/cutter.hpp"

namespace hybridctl::toolpaths::pocket {

struct ToolModel {
  std::vector<geometry::AxialSection> cutting, body;
  geometry::AxialBody whole_guard;  // cutter + body, conservative: what must not touch `keep`
  geometry::AxialBody body_guard;   // body alone, conservative: what must not touch material
  double cutter_radius = 0;
  double max_radius = 0;
  int body_first_level = 0;  // the lowest level the body reaches
  bool widening = true;      // radius never shrinks going up the axis
  // The cutter as discs: for each distinct radius (voxels), the levels above the tip
  // that have it, exactly as geometry::offsets_of makes the cutter's voxel offsets.
  std::vector<std::pair<double, std::vector<int>>> cutter_discs;
  // The body (shank, holder) as discs: radius (voxels, conservative along the axis as the
  // guard is) and the lowest level above the tip where it starts.
  std::vector<std::pair<double, int>> body_discs;
  // The running maximum of the squared radius along the axis (the whole tool, the cutter,
  // the body), sampled every `profile_step` mm from the tip to a voxel past the shank.
  std::vector<double> run_whole, run_cutter, run_body;
  double profile_step = 0;
};

// The lowest height above the tip (mm) at which the running profile `run` reaches the
// squared distance `rho2` (mm^2) from the axis, rounded down by a sample (safe); infinity
// when never.
double first_reach(const std::vector<double>& run, double step, double rho2);

// The model of `tool` (its defaults applied: instruments::with_defaults) on a lattice of
// voxel size `h`.
ToolModel make_tool(const config::CuttingTool& tool, double h);

// For a column at (dx, dy) voxels from the tool axis: the lowest height above the tip
// (mm) at which the tool (or its cutter, or its body) reaches that far out; infinity when
// never. A tool moving vertically down to tip height z sweeps exactly the heights >= z +
// zmin.
struct ReachOffset {
  int dx = 0, dy = 0;
  double zmin_whole = std::numeric_limits<double>::infinity(), zmin_cutter = zmin_whole, zmin_body = zmin_whole;
};

// Every column the whole tool reaches.
std::vector<ReachOffset> reach_offsets(const ToolModel& m, double h);

}  // namespace hybridctl::toolpaths::pocket
