#pragma once
// Z-level pocket milling: the toolpath that removes a subtractive action's region of
// influence (ROI) without ever touching the material that must remain
// (docs/toolpaths.md is the full description).
//
//   Toolpath p = pocket_path(roi, keep, stock_before, tool, setup);
//
// Work frame (toolpaths/setup_frame.hpp): the tool axis is +Z. Tool positions are the tool
// tip (the lowest point of the cutter, on its axis), on voxel centres sideways (the wall
// finishing passes excepted), at the levels' heights. Levels go top-down at the tool's
// step_down and include every floor of the ROI. At each level the tool tip stays in the
// allowed region: where the whole tool (cutter, shank, holder) touches no voxel of
// `keep`, computed once in 3D by dilating `keep` with the reflected tool. The useful
// part of a level (allowed tips whose cutter meets ROI material still there) is cleared
// by zigzag rows at step_over plus a pass along its edge (or by contour-parallel rings),
// linked by feed moves inside the allowed region, otherwise by retracting to safe_z.
// Entries plunge only where the tool meets no material on the way down; elsewhere they
// lead in sideways from air, or ramp along the first segment at ramp_angle_deg.
// Given the design's STL (PocketOptions::design), a flat cutter then follows the design's
// real walls at each level (wall finishing), off the lattice, and finishes the walls and
// tops of what deposits laid (PocketOptions::laid) where the voxels show nothing to remove;
// a ball or bull nose finishes the faces under the region by a drop-cutter raster on the
// STL (surface finishing).

#include <memory>
#include <optional>

#include "config/machine.hpp"
#include "toolpaths/toolpath.hpp"
#include "geometry/mesh.hpp"
#include "geometry/solid.hpp"

namespace hybridctl::toolpaths {

enum class PocketStrategy {
  Zigzag,   // rows at step_over (direction per `raster`), plus an edge pass per `wall_pass`
  Offsets,  // contour-parallel rings inward from the edge of each level's region
};

enum class PocketRaster {
  AlongX,     // zigzag rows parallel to the work frame's X axis
  AlongY,     // rows parallel to Y
  Alternate,  // X on the first level, Y on the next, and so on
};

enum class WallPass {
  None,     // rows only: material next to walls between rows may stay
  Contour,  // after the rows, one pass along the edge of the level's useful region
};

struct PocketOptions {
  PocketStrategy strategy = PocketStrategy::Zigzag;
  PocketRaster raster = PocketRaster::AlongX;
  WallPass wall_pass = WallPass::Contour;  // Zigzag only; Offsets always follow the edge
  // Steepest descent of a ramp, degrees from the horizontal; > 0 and <= 90.
  double ramp_angle_deg = 3.0;
  // Rapids stop this far (mm) above the material the tool would meet at an entry.
  double retract_clearance = 1.0;
  // Rapids keep this much (mm) further from the plan's material, sideways and above: the
  // stock as built is not the plan's voxels (deposition beads spill up to ~0.7 mm past
  // them, docs/toolpaths.md), and a rapid must not meet what a feed move would shave off.
  double material_allowance = 1.0;
  // safe_z: this far (mm) above the highest material in the domain.
  double safe_clearance = 5.0;
  // The design's faces that face the tool (work frame, each level at one height: exact,
  // from the STL: geometry::axis_square_faces of plan::PlanFile::design_mesh). A flat cutter's level over such a floor cuts
  // at the floor's height rather than at the voxel centre above it, and a level with nothing
  // to keep under it at the bottom of its voxels: on the voxels the same cut, on the part
  // no lip of up to a voxel left on the floor (docs/toolpaths.md, "Levels").
  std::vector<geometry::Triangle> floors;
  // The design's surface (work frame: the STL's facets turned as the floors are, closed,
  // duplicate facets removed: geometry::clean_mesh), shared rather than copied per action;
  // null or empty for a design made on voxels, or for an action that cuts into the design
  // on purpose (a later deposit lays it again). With it, a flat cutter finishes the walls
  // exactly (docs/toolpaths.md, "Wall finishing"): after each level is roughed, its side
  // follows the design's real walls at the level's height (toolpaths/wall_finish.hpp), and
  // the roughing keeps the cutter off the design between voxel centres too, design voxels
  // of the ROI included.
  std::shared_ptr<const std::vector<geometry::Triangle>> design;
  // The design's voxels (part frame, on the solids' lattice), which the finishing passes
  // leave to the exact surface: null makes them from `design` (centres inside it, as the
  // planner voxelizes).
  const geometry::Solid* design_voxels = nullptr;
  // Material a deposit laid that no removal has finished since (part frame, on the
  // solids' lattice), or null. With `design` and a flat cutter, the walls where it borders
  // the finishing region are finished at every step-down of its height, also where the
  // voxels hold nothing to remove: a bead stands past the design by up to its head's
  // accuracy and the slack it is laid with, which no voxel shows (docs/toolpaths.md, "Wall
  // finishing").
  const geometry::Solid* laid = nullptr;
  // Wall finishing on (default) or off (the roughing alone, for comparison).
  bool finish_walls = true;
  // Surface finishing with ball and bull-nose cutters, given `design` (docs/toolpaths.md,
  // "Surface finishing"): after the levels, a drop-cutter raster on the design's real
  // surface wherever the region lies on it, its rows close enough that the scallops on a
  // flat face stand at most `scallop` mm (the tool's step_over caps the step). Off: the
  // Z-levels alone, as they leave a curved face (a staircase of step-downs).
  bool finish_surfaces = true;
  double scallop = 0.1;
  // The region the action may remove (part frame, on the solids' lattice: its primitive's),
  // or null for the ROI: the faces it finishes are the design's faces next to it, also
  // where an earlier action left less than a voxel on them (within the ROI's reach).
  const geometry::Solid* finish_region = nullptr;
  // Overrides of the tool's step_down and step_over (mm).
  std::optional<double> step_down;
  std::optional<double> step_over;
};

// The milling toolpath of one subtractive action.
//   roi           material to remove, part frame
//   keep          material that must remain (the state after the action): never touched
//   stock_before  material present before the action (may be empty: then the ROI is
//                 taken as present); material in it that is neither ROI nor `keep` is
//                 not touched either
//   tool          the cutting tool: diameter, type, flute, shank, holder, feeds, steps
//   setup         its approach becomes the work frame's +Z; its name is recorded
// All solids on one lattice (std::invalid_argument otherwise). Moves in mm, work frame.
// Defects (Toolpath::defects, the part will be wrong): no tool position reaches the ROI
// at all ("unreachable"). Warnings: ROI the tool cannot reach (volume and extent: corners
// a round tool leaves; the part as built judges them against the tolerance), entries with
// no room to ramp, passes skipped because the shank or holder would meet material, wall
// finishing passes left out for want of a lead-in or lead-out from air.
Toolpath pocket_path(const geometry::Solid& roi, const geometry::Solid& keep, const geometry::Solid& stock_before,
                     const config::CuttingTool& tool, const config::Setup& setup, const PocketOptions& options = {});

}  // namespace hybridctl::toolpaths
