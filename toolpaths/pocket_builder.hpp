#pragma once
// The pocket generator's state while it builds one toolpath (internal to
// toolpaths/pocket_*.cpp; pocket_path.hpp is the interface, docs/toolpaths.md the
// description). pocket_path.cpp holds the steps of a run (material, allowed tips, levels,
// clearing a level) and the moves; pocket_entry.cpp how the tool gets down to a pass
// (plunge in air, lead-in, ramp); pocket_finish.cpp the wall finishing passes of a level
// (off the lattice, on the design's real walls: toolpaths/wall_finish.hpp).

#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "geometry/solid.hpp"
#include "toolpaths/drop_cutter.hpp"
#include "toolpaths/pocket_cells.hpp"
#include "toolpaths/pocket_path.hpp"
#include "toolpaths/pocket_tool.hpp"
#include "toolpaths/wall_finish.hpp"

namespace hybridctl::toolpaths::pocket {

// Wall finishing's working parts (pocket_finish.cpp): what a tip height's passes must keep
// to and clear of, and a piece of its contour to finish.
struct FinishLevel;
struct FinishRun;

// A wall finishing pass as it is cut: in air to the wall along the lead-in (a quarter
// circle tangent to the wall, or a straight move), round the wall, out along the lead-out.
struct FinishPass {
  std::vector<Point2> lead_in;   // from where the tool comes down, up to (not including) body's first
  std::vector<Point2> body;      // on the wall
  std::vector<Point2> lead_out;  // after body's last, to where the tool leaves
};

inline constexpr double kInf = std::numeric_limits<double>::infinity();
// Heights are compared with this slack (mm): a tool tip this close above a voxel centre
// still counts as touching it.
inline constexpr double kHeightSlack = 1e-6;

// How many of the nearest starts are tried for a feed link, and for an entry from air,
// before retracting or ramping.
inline constexpr std::size_t kLinkCandidates = 8;
inline constexpr std::size_t kEntryCandidates = 12;

// mm with three decimals, for comments and warnings.
std::string mm(double v);

class PocketBuilder {
 public:
  PocketBuilder(const config::CuttingTool& tool, const PocketOptions& options, Toolpath& path)
      : tool_(tool), options_(options), path_(path) {}

  // `design`: the design's voxels in the work frame, or null (then made from
  // PocketOptions::design when finishing); `finish_region`: PocketOptions::finish_region in
  // the work frame, or null for the ROI.
  // `laid`: PocketOptions::laid in the work frame, or null.
  Toolpath& run(const geometry::Solid& roi, const geometry::Solid& keep, const geometry::Solid& stock,
                const geometry::Solid* design = nullptr, const geometry::Solid* finish_region = nullptr,
                const geometry::Solid* laid = nullptr);

 private:
  using Solid = geometry::Solid;
  using IndexBox = geometry::IndexBox;
  using Vec3 = geometry::Vec3;
  // Levels, top-down (voxel layer indices of the tip).
  using Levels = std::set<int, std::greater<int>>;

  // The steps of a run.
  void use_step_sizes();
  bool take_material(const Solid& roi, const Solid& keep, const Solid& stock);
  Solid allowed_tips() const;
  void start_column_tops();
  Levels cutting_levels() const;
  // Whether this run can finish walls on the STL (a flat cutter, given the design).
  bool finishes_walls() const;
  // The walls of laid material next to the region: the levels that finish them, and where
  // that material is (voxel indices, work frame; empty when none).
  struct LaidWalls {
    Levels levels;
    IndexBox box;
  };
  LaidWalls laid_walls(const Solid& laid, const Solid& region) const;
  // The tops of laid material under a floor of the design, to skim at the floor's height:
  // per level, the cells (tip domain); sets those levels' heights.
  std::map<int, SliceMask> laid_floors(const Solid& laid, const Solid& region);
  void held_rows(int y, int z, std::vector<std::uint64_t>& held) const;
  SliceMask usable_tips(const Solid& allowed, int k) const;
  SliceMask useful_tips(const SliceMask& usable, int k) const;
  void clear_level(const SliceMask& useful, const SliceMask& usable, int k, int level_number);
  void report_what_stays();

  double centre_z(int k) const { return lattice_.origin.z + (k + 0.5) * h_; }
  // The tip's height at level k: centre_z(k), or lower within the voxel (exact_heights).
  double level_z(int k) const {
    const auto it = level_heights_.find(k);
    return it == level_heights_.end() ? centre_z(k) : it->second;
  }
  std::map<int, double> exact_heights(const Levels& levels) const;
  double floor_height(int k) const;
  Vec3 at_cell(Cell c, double z) const {
    return {lattice_.origin.x + (c.x + 0.5) * h_, lattice_.origin.y + (c.y + 0.5) * h_, z};
  }
  int top_at(int x, int y) const {
    if (x < tops_box_.lo.x || x >= tops_box_.hi.x || y < tops_box_.lo.y || y >= tops_box_.hi.y) return kNoVoxel;
    return tops_[std::size_t(y - tops_box_.lo.y) * std::size_t(tops_box_.hi.x - tops_box_.lo.x) +
                 std::size_t(x - tops_box_.lo.x)];
  }
  // The lowest tip height from which the tool (or only its cutter, or only its body) can
  // come straight down from safe_z without meeting material; -infinity when nothing
  // is in reach. Heights at or below it touch material.
  enum class Part { Whole, Cutter, Body };
  double contact_height(Cell c, Part part) const;
  // Where a rapid coming down over `c` stops: material_allowance beside and above the
  // material the whole tool would meet there, retract_clearance above that, and not below
  // `at_least` + retract_clearance.
  double rapid_stop(Cell c, double at_least) const;
  void refresh_tops(const IndexBox& xy);

  void move(MoveKind kind, Vec3 to, double feed, bool cutting, std::string comment = {});
  void retract();
  void cut_paths(std::vector<CellPath> todo, int k, const SliceMask& usable);
  // Feeds from the current position to the nearest of the starts `cands` of `todo` that a
  // link inside `usable` reaches, and cuts that path; false when none is in reach.
  bool link_to_next(std::vector<CellPath>& todo, const std::vector<Candidate>& cands, int k, const SliceMask& usable);
  void cut_along(const CellPath& p, double zk);
  CellPath take(std::vector<CellPath>& todo, const Candidate& c) const;
  Cell current_cell() const {
    return {int(std::floor((at_.x - lattice_.origin.x) / h_)), int(std::floor((at_.y - lattice_.origin.y) / h_))};
  }
  void stamp_run(int k);

  // Entries (pocket_entry.cpp).
  bool enter(const CellPath& p, int k, const SliceMask& usable);
  // Where the tool can come straight down in air and reach the start of `p` at level k:
  // the start itself, or a cell before it on the line of its first leg (a lead-in).
  std::optional<Cell> air_entry(const CellPath& p, int k, const SliceMask& usable);
  bool in_air(Cell c, int k);
  // Rapids from safe_z (or from the first move) to above `c`, then down to `stop`.
  void go_above(Cell c, double stop);
  void go_above(Point2 p, double stop);
  void plunge_in_air(Cell a, Cell b, double zk);
  void ramp_in(const CellPath& p, double zk, const SliceMask& usable);
  // Where the ramp from `b` along `d` over `m` cells starts: where the cutter first meets
  // material over its cells.
  double ramp_start(Cell b, Cell d, int m, double zk) const;

  // Wall finishing (pocket_finish.cpp). Whether this run finishes walls, and what it needs;
  // `region`: what the action may remove (the walls next to it are finished).
  void start_finishing(const Solid& region, const Solid* design);
  // The tip positions at height z where the tool would cut into the design.
  TipKeepOut keep_out_at(double z) const;
  // The cells of the tip domain whose centres lie in `region` (boundary included).
  SliceMask cells_in(const TipKeepOut& region) const;
  // The finishing passes with the tip at z (level k's height, or a face's above it) along
  // the boundary of `keep_out`, where they finish what level k removes (the ROI's layers
  // [k, k_above)).
  void finish_walls(const TipKeepOut& keep_out, int k, int k_above, double z);
  // The finishing passes under the lowest level (k_low, its tip at z_low), for what a
  // deposit laid below its voxels.
  void finish_walls_below(int k_low, double z_low);
  // What those passes must keep clear of; nothing when no wall there is this level's.
  std::optional<FinishLevel> finish_level(const TipKeepOut& keep_out, int k, int k_above, double z) const;
  std::optional<std::vector<Point2>> finish_lead(const FinishLevel& f, Point2 p, Point2 t, bool in) const;
  // A run with its lead-in and lead-out, or nothing when it has none.
  std::optional<FinishPass> finish_pass(const FinishLevel& f, const FinishRun& run, Point2 from) const;
  void cut_finish_pass(const FinishLevel& f, const FinishPass& pass);
  // contact_height at any point (mm, work frame), not only at a cell's centre: exact for
  // the voxels' column tops (`tops`: tops_, or another set's over tops_box_).
  double contact_height_at(Point2 p, Part part) const { return contact_height_at(p, part, tops_); }
  double contact_height_at(Point2 p, Part part, const std::vector<int>& tops) const;
  double rapid_stop_at(Point2 p, double at_least) const;
  Cell cell_of(Point2 p) const {
    return {int(std::floor((p.x - lattice_.origin.x) / h_)), int(std::floor((p.y - lattice_.origin.y) / h_))};
  }
  // Removes from the material still there what the cutter takes along the polyline at `z`.
  void stamp_polyline(const std::vector<Point2>& points, double z);

  // Surface finishing (pocket_surface.cpp): ball and bull noses on the design's STL.
  // `region`: what the action may remove; the faces next to it are finished.
  void start_surface_finishing(const Solid& region, const Solid* design);
  Solid stays_besides_design() const;
  void finish_surfaces();
  double finish_surface_rows(const CellBox& box, bool along_x, double steep_cos);
  // The lowest tip height at p clear of the design's surface, of what must stay that is
  // not design, and with the body clear of all material; -infinity when nothing is there.
  double surface_tip_at(Point2 p) const;
  // The path along the straight line a-b at surface_tip_at's heights: samples, refined
  // where the chord between two would dip under the surface, thinned where it would not.
  std::vector<Vec3> surface_line(Point2 a, Point2 b) const;
  bool in_surface_domain(Point2 p) const;
  // The tip cells where roughing at height z would come closer to the STL than it leaves
  // for the finishing passes (none when the run does not finish surfaces).
  SliceMask under_surface(double z) const;
  // One pass along `pts`, reached along `link` from where the tool is (over the surface),
  // or from above when `link` is empty.
  void cut_surface_pass(const std::vector<Vec3>& pts, const std::vector<Vec3>& link);
  // Removes from the material still there what the cutter takes along `pts`.
  void stamp_surface_pass(const std::vector<Vec3>& pts);

  config::CuttingTool tool_;
  PocketOptions options_;
  Toolpath& path_;
  geometry::Lattice lattice_;
  double h_ = 1;
  ToolModel model_;
  std::vector<ReachOffset> reach_;
  double step_over_ = 0;     // mm
  int down_ = 1, over_ = 1;  // step down and step over in whole voxels
  IndexBox all_;             // every voxel of the ROI, keep and stock
  IndexBox work_;            // tip domain
  Solid remaining_, untouchable_;
  // What must stay that the exact finishing passes must not cut either: what stays, less
  // the design (the STL keeps the passes off it) and the material within a voxel of it (the
  // band the plan leaves free: taking it only brings the part closer to the STL). Set when
  // finishing starts (stays_besides_design).
  Solid stays_;
  IndexBox tops_box_;
  std::vector<int> tops_, untouchable_tops_;
  double safe_z_ = 0;
  Vec3 at_{};
  // The spindle speed the feed moves run at from here (0: the tool's): the finishing
  // passes run at the tool's finishing speed.
  double spindle_ = 0;
  bool started_ = false;
  bool at_level_ = false;
  int level_ = 0;                        // the level being cut (voxel layer of the tip)
  std::map<int, double> level_heights_;  // levels whose tip is not at the voxel centre
  std::vector<Cell> run_cells_;
  std::string pending_comment_;
  std::map<std::pair<int, int>, bool> air_cache_;  // per level, until the next removal
  int plunges_into_material_ = 0, skipped_entries_ = 0;
  // Wall finishing.
  bool finishing_ = false;
  std::vector<ToolBand> finish_bands_;
  double rough_margin_ = 0;  // mm the roughing's tips keep beyond the keep-out region
  Solid roi_, design_;       // work frame; roi_: what the action may remove (finishing)
  std::vector<double> face_heights_;  // of the design's faces square to the axis, top-down
  // Surface finishing.
  std::shared_ptr<const DropCutter> drop_;
  std::vector<int> obstacle_tops_;  // over tops_box_: what must stay that is not design
  // Over tops_box_: the highest of those within the cutter's reach, and of all material
  // within the whole tool's, when finishing starts.
  std::vector<int> obstacle_near_, material_near_;
  SliceMask surface_domain_;        // tip cells whose passes finish this region's faces
  double surface_step_over_ = 0;    // mm between rows
  double surface_floor_ = 0;        // mm: the region's bottom, below which no pass goes
  std::vector<double> rough_tips_;  // over work_'s cells: the lowest roughing tip height
  int surface_passes_ = 0;
  int finish_passes_ = 0, finish_skipped_ = 0;
  double finish_length_ = 0, finish_skipped_length_ = 0;  // mm
};

}  // namespace hybridctl::toolpaths::pocket
