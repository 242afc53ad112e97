#pragma once
// Raster deposition: the toolpath that lays down an additive action's region of
// influence (ROI) layer by layer (docs/toolpaths.md is the full description).
//
//   Toolpath p = deposition_path(roi, existing, head, setup);
//
// Work frame (toolpaths/setup_frame.hpp): the setup's approach direction is +Z. Layers of the
// head's layer_height go bottom-up from the ROI's lowest voxel face. A layer's region is
// the ROI's voxels whose centres lie in the layer's band [z, z + layer_height) (the
// voxel at the band's middle when it holds no centre). By default a contour bead runs
// along the region's edge first; raster lines at hatch_spacing, at an angle that changes
// from layer to layer, are clipped to the region inside it; deposition is on along the
// contour and the clipped segments only. Between segments the head lifts by travel_clearance
// above the material under the travel (existing material and everything deposited so
// far, within the nozzle's radius) and comes down again. Rapids never touch material,
// even with the bead's volume: near the work (approach_gap above the material under the
// bead) the head moves at feed with deposition off.
//
// The programmed point is the bottom of the bead on its axis: the surface the bead is
// laid on (z = the layer's bottom).

#include <memory>
#include <optional>
#include <vector>

#include "config/machine.hpp"
#include "toolpaths/toolpath.hpp"
#include "geometry/mesh.hpp"
#include "geometry/solid.hpp"

namespace hybridctl::toolpaths {

// Where a layer's contour (a pass along the region's edge, half a bead inside it) goes.
// Contour first is what slicers for DED and wire-arc do: rasters alone end in rounded
// bead ends that leave scallops along every edge not parallel to them, which on a thin
// wall or a ring are more than a tolerance of a few tenths deep.
enum class ContourPass {
  None,          // rasters only
  BeforeInfill,  // contour first, then rasters inside it
  AfterInfill,   // rasters inside the contour first, then the contour
};

struct DepositionOptions {
  // Raster angle of layer i, degrees from the work frame's +X towards +Y: the list is
  // used cyclically. The default alternates 0 and 90 degrees. Any angle is allowed.
  std::vector<double> raster_angles_deg = {0.0, 90.0};
  ContourPass contour = ContourPass::BeforeInfill;
  // How far segment ends stay inside the region along the raster (mm), so that the
  // bead's end does not spill out. Default: half the bead width. An end against material
  // already there (the existing solid, in the same layer) runs to the region's edge: the
  // bead's end fuses with that wall instead of leaving notches between the tracks.
  std::optional<double> edge_inset;
  // Clipped raster segments shorter than this (mm, before the inset) are dropped, and so
  // are contour chains shorter than it. Default: the bead width.
  std::optional<double> min_segment_length;
  // The build plate, mm in the work frame: deposit lying on it is supported. Default: the
  // bottom face of the lowest voxel of the ROI and the existing material.
  std::optional<double> build_plate_z;
  // Deposit is supported when material (existing, deposited, the plate) ends at most this
  // far (mm) below the layer's bottom. Default: half a voxel (the voxel layer under the bead's bottom).
  std::optional<double> support_gap;
  // Deposit within this distance (mm, sideways) of supported deposit counts as supported:
  // a bead may overhang its support by a fraction of its width; farther is not laid.
  // Default: the head's one-layer reach (instruments/support_rule.hpp), at most half the
  // bead width.
  std::optional<double> overhang_reach;
  // Rapids stop this far (mm) above the material under the bead's footprint (beads
  // counted at their full height); the head comes down onto the surface, and leaves a
  // bead it has just laid, at feed with deposition off.
  double approach_gap = 0.5;
  // The T number for a head whose tool_number is unset (0, e.g. built by hand); the
  // machine loader always sets it (default 100 + the head's index). Plan export passes
  // instruments::head_tool_number(machine, index), as the simulated machine numbers heads.
  int fallback_tool_number = 0;
  // The voxels of the ROI the plan counts on this action for (part frame, the ROI's
  // lattice), when the ROI also holds what earlier actions were meant to lay and did not:
  // executed from the material really present, an action's ROI is its primitive less that
  // material. Of those others, what lies under existing material is left out with a
  // warning, not a defect: the plan never counted on this action for it, and what the part
  // then lacks is judged where the part is judged (validation compares it with the
  // design). Null: all of the ROI is counted on.
  const geometry::Solid* counted_on = nullptr;
  // A near-net deposit's design (work frame; its surface, closed: the STL's facets turned
  // into the setup's frame): each layer's passes are kept where the bead's axis lies within
  // the design's exact cross-section at the layer's middle shrunk by half a bead, so that
  // its beads end on the design's real walls, not half a voxel past them where a wall runs
  // through voxel centres. A contour point out of that region (grown by near_net_slack)
  // by at most a voxel goes to its edge, a raster is cut at it; a layer whose section holds no such place keeps
  // its voxel passes. Its layers are a little thinner than the head's layer height where
  // that makes the last one end on the deposit's top. Null: passes on the voxels alone (an overfill deposit's, whose beads
  // stand out of the design on purpose).
  std::shared_ptr<const std::vector<geometry::Triangle>> near_net_design;
  // How far (mm) a near-net bead may stand past the design's wall before it is pulled in:
  // plan export gives half of what the part's tolerance leaves beyond the head's
  // as-deposited accuracy, so that passes move no more than they must (a pass pulled in
  // comes apart from the rasters beside it a little).
  double near_net_slack = 0;
};

// The deposition toolpath of one additive action.
//   roi       voxels to deposit, part frame (the action's region of influence)
//   existing  material present before the action, part frame, same lattice (may be empty)
//   head      the additive head: bead, layer_height, hatch_spacing, travel_clearance, feed
//   setup     the setup: its approach becomes the work frame's +Z; its name is recorded
// Moves are in mm in the work frame. Defects (Toolpath::defects, the part will be wrong):
// ROI under existing material, not reachable from the approach side, is skipped
// ("layer_skipped", one per layer; a warning where the options do not count on it). Warnings: overhangs (region with nothing below: not laid),
// dropped short segments. A layer height, hatch spacing or feed left at 0 takes the machine
// file's default (0.8 x bead height, 0.7 x bead width, 1000 mm/min). Throws
// std::invalid_argument on solids on different lattices or a head without a bead.
Toolpath deposition_path(const geometry::Solid& roi, const geometry::Solid& existing, const config::AdditiveHead& head,
                         const config::Setup& setup, const DepositionOptions& options = {});

}  // namespace hybridctl::toolpaths
