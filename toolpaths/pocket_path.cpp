#include "toolpaths/pocket_path.hpp"

#include <algorithm>
#include <cstdint>
#include <span>
#include <vector>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <optional>
#include <string>

#include "common/number_text.hpp"
#include "geometry/morphology.hpp"
#include "instruments/cutter.hpp"
#include "toolpaths/pocket_builder.hpp"
#include "toolpaths/setup_frame.hpp"
#include "toolpaths/slices.hpp"

// Z-level pocket milling: the steps of a run and the moves (pocket_builder.hpp). The tool
// is pocket_tool.hpp's, the paths of a level pocket_cells.hpp's, the entries
// pocket_entry.cpp's.

namespace hybridctl::toolpaths {
namespace pocket {

std::string mm(double v) { return fixed_number(v, 3); }

void PocketBuilder::move(MoveKind kind, Vec3 to, double feed, bool cutting, std::string comment) {
  if (to == at_ && started_) return;
  PathMove m;
  m.kind = kind;
  m.to = to;
  m.feed = kind == MoveKind::Rapid ? 0 : feed;
  m.spindle = kind == MoveKind::Rapid ? 0 : spindle_;
  m.process_on = cutting;
  if (!pending_comment_.empty()) {
    m.comment = pending_comment_ + (comment.empty() ? "" : "; " + comment);
    pending_comment_.clear();
  } else {
    m.comment = std::move(comment);
  }
  path_.moves.push_back(std::move(m));
  at_ = to;
}

double PocketBuilder::contact_height(Cell c, Part part) const {
  double need = -kInf;
  for (const ReachOffset& o : reach_) {
    const double zmin = part == Part::Whole ? o.zmin_whole : part == Part::Cutter ? o.zmin_cutter : o.zmin_body;
    if (std::isinf(zmin)) continue;
    const int top = top_at(c.x + o.dx, c.y + o.dy);
    if (top == kNoVoxel) continue;
    need = std::max(need, centre_z(top) - zmin);
  }
  return need;
}

double PocketBuilder::rapid_stop(Cell c, double at_least) const {
  const int r = int(std::ceil(options_.material_allowance / h_ - 1e-9));
  double top = contact_height(c, Part::Whole);
  for (int dy = -r; dy <= r; ++dy)
    for (int dx = -r; dx <= r; ++dx)
      if (dx * dx + dy * dy <= r * r) top = std::max(top, contact_height({c.x + dx, c.y + dy}, Part::Whole));
  return std::max(top + options_.material_allowance, at_least) + options_.retract_clearance;
}

void PocketBuilder::refresh_tops(const IndexBox& xy) {
  const IndexBox box = geometry::box_intersection(
      {{xy.lo.x, xy.lo.y, tops_box_.lo.z}, {xy.hi.x, xy.hi.y, tops_box_.hi.z}}, tops_box_);
  if (box.empty()) return;
  const std::vector<int> rem = column_top_indices(remaining_, box);
  const int nx = box.hi.x - box.lo.x, tnx = tops_box_.hi.x - tops_box_.lo.x;
  for (int y = box.lo.y; y < box.hi.y; ++y)
    for (int x = box.lo.x; x < box.hi.x; ++x) {
      const std::size_t t = std::size_t(y - tops_box_.lo.y) * std::size_t(tnx) + std::size_t(x - tops_box_.lo.x);
      tops_[t] = std::max(untouchable_tops_[t], rem[std::size_t(y - box.lo.y) * std::size_t(nx) + std::size_t(x - box.lo.x)]);
    }
}

// Removes what the cutter took along the cells visited at level k since the last entry.
void PocketBuilder::stamp_run(int k) {
  if (run_cells_.empty()) return;
  const std::vector<Cell> cells = run_cells_;
  int x0 = cells[0].x, x1 = x0, y0 = cells[0].y, y1 = y0;
  for (const Cell& c : cells) {
    x0 = std::min(x0, c.x), x1 = std::max(x1, c.x), y0 = std::min(y0, c.y), y1 = std::max(y1, c.y);
  }
  run_cells_.clear();
  air_cache_.clear();
  // The cutter's discs grown around the tips, level by level above them.
  const int R = int(std::ceil(model_.cutter_radius / h_)) + 1;
  SliceMask tips(x0 - R, y0 - R, x1 - x0 + 1 + 2 * R, y1 - y0 + 1 + 2 * R);
  for (const Cell& c : cells) tips.set(c.x, c.y);
  const IndexBox storage = remaining_.storage_box();
  const int first_word = remaining_.first_word(), words = remaining_.words_per_row();
  std::vector<std::uint64_t> row_mask(std::size_t(words > 0 ? words : 0));
  for (const auto& [radius, levels] : model_.cutter_discs) {
    const SliceMask swept = grow_by_disc(tips, radius);
    // Row by row: the swept cells as words of the stored row, cleared at every level.
    for (int y = std::max(swept.y0(), storage.lo.y); y < std::min(swept.y0() + swept.ny(), storage.hi.y); ++y) {
      std::fill(row_mask.begin(), row_mask.end(), 0);
      bool any = false;
      for (int x = std::max(swept.x0(), storage.lo.x); x < std::min(swept.x0() + swept.nx(), storage.hi.x); ++x)
        if (swept.at(x, y)) {
          row_mask[std::size_t((x >> 6) - first_word)] |= std::uint64_t{1} << (x & 63);
          any = true;
        }
      if (!any) continue;
      for (const int t : levels) {
        if (k + t < storage.lo.z || k + t >= storage.hi.z) continue;
        const std::span<std::uint64_t> r = remaining_.row(y, k + t);
        for (std::size_t w = 0; w < r.size(); ++w) r[w] &= ~row_mask[w];
      }
    }
  }
  refresh_tops({{x0 - R, y0 - R, 0}, {x1 + 1 + R, y1 + 1 + R, 1}});
}

void PocketBuilder::retract() {
  if (!at_level_) return;
  stamp_run(level_);
  if (!model_.widening) {
    // Going up, a cutter wider than the shank above it sweeps new ground: feed up until
    // the tool is clear of everything still there.
    const Cell c{int(std::floor((at_.x - lattice_.origin.x) / h_)), int(std::floor((at_.y - lattice_.origin.y) / h_))};
    const double clear = contact_height(c, Part::Whole) + options_.retract_clearance;
    if (clear > at_.z) move(MoveKind::Feed, {at_.x, at_.y, std::min(clear, safe_z_)}, tool_.plunge_feed, true, "feed out");
  }
  move(MoveKind::Rapid, {at_.x, at_.y, safe_z_}, 0, false);
  at_level_ = false;
}

CellPath PocketBuilder::take(std::vector<CellPath>& todo, const Candidate& c) const {
  CellPath p = oriented(todo[c.path], c);
  todo[c.path] = std::move(todo.back());
  todo.pop_back();
  return p;
}

void PocketBuilder::cut_along(const CellPath& p, double zk) {
  for (std::size_t i = 1; i < p.points.size(); ++i) {
    for_leg_cells(p.points[i - 1], p.points[i], [&](Cell v) { run_cells_.push_back(v); });
    move(MoveKind::Feed, at_cell(p.points[i], zk), tool_.feed, true);
  }
}

bool PocketBuilder::link_to_next(std::vector<CellPath>& todo, const std::vector<Candidate>& cands, int k,
                                 const SliceMask& usable) {
  const double zk = level_z(k);
  const Cell cur = current_cell();
  for (std::size_t i = 0; i < cands.size() && i < kLinkCandidates; ++i) {
    const CellPath probe = oriented(todo[cands[i].path], cands[i]);
    if (const auto link = link_cells(cur, probe.points.front(), usable)) {
      const CellPath p = take(todo, cands[i]);
      Cell prev = cur;
      for (const Cell& c : *link) {
        for_leg_cells(prev, c, [&](Cell v) { run_cells_.push_back(v); });
        move(MoveKind::Feed, at_cell(c, zk), tool_.feed, true);
        prev = c;
      }
      cut_along(p, zk);
      return true;
    }
  }
  return false;
}

void PocketBuilder::cut_paths(std::vector<CellPath> todo, int k, const SliceMask& usable) {
  while (!todo.empty()) {
    const Cell cur = started_ ? current_cell() : todo.front().points.front();
    const std::vector<Candidate> cands = candidates(todo, cur);
    if (at_level_) {
      // Feed over to the nearest start that a link inside the usable region reaches.
      if (link_to_next(todo, cands, k, usable)) continue;
      retract();
    }
    // Enter at the nearest start reachable from air, else at the nearest.
    std::size_t pick = 0;
    for (std::size_t i = 0; i < cands.size() && i < kEntryCandidates; ++i)
      if (air_entry(oriented(todo[cands[i].path], cands[i]), k, usable)) {
        pick = i;
        break;
      }
    const CellPath p = take(todo, cands[pick]);
    if (enter(p, k, usable)) cut_along(p, level_z(k));
  }
}

void PocketBuilder::use_step_sizes() {
  double step_down = options_.step_down.value_or(tool_.step_down);
  if (step_down > tool_.flute_length) {
    // Deeper than the flutes, the shank would have to push through what they leave.
    path_.warnings.push_back("step down " + mm(step_down) + " mm is more than the flute length; using " +
                             mm(tool_.flute_length) + " mm");
    step_down = tool_.flute_length;
  }
  step_over_ = options_.step_over.value_or(tool_.step_over);
  if (!(step_down > 0) || !(step_over_ > 0)) throw std::invalid_argument("pocket_path: step_down and step_over must be > 0");
  down_ = std::max(1, int(std::floor(step_down / h_ + 1e-9)));
  over_ = std::max(1, int(std::floor(step_over_ / h_ + 1e-9)));
}

// What is there: the ROI still to remove, and what must not be touched; safe_z above it
// all. False when there is nothing to remove.
bool PocketBuilder::take_material(const Solid& roi, const Solid& keep, const Solid& stock) {
  remaining_ = stock.empty() ? roi : geometry::intersect(roi, stock);
  if (!keep.empty()) remaining_ = geometry::subtract(remaining_, keep);
  untouchable_ = keep.empty() ? Solid(lattice_, {}) : keep;
  if (!stock.empty()) untouchable_ = geometry::unite(untouchable_, geometry::subtract(stock, roi));
  all_ = geometry::box_union(roi.bounding_box(), geometry::box_union(keep.bounding_box(), stock.bounding_box()));
  safe_z_ = (all_.empty() ? lattice_.origin.z : lattice_.origin.z + all_.hi.z * h_) + options_.safe_clearance;
  path_.safe_z = safe_z_;
  return !remaining_.bounding_box().empty();
}

// The whole tool clear of `untouchable`, at this height and every height above it (so
// every vertical move out of an allowed tip is clear as well), over the tip domain: around
// the ROI by the cutter (and room to lead in), from the ROI's bottom to above all material.
PocketBuilder::Solid PocketBuilder::allowed_tips() const {
  Solid allowed = untouchable_.empty()
                      ? Solid::filled(lattice_, work_)
                      : geometry::complement(geometry::dilate(untouchable_, geometry::reflected(model_.whole_guard), work_), work_);
  for (int z = work_.hi.z - 2; z >= work_.lo.z; --z)
    for (int y = work_.lo.y; y < work_.hi.y; ++y) {
      auto row = allowed.row(y, z);
      const auto above = allowed.row(y, z + 1);
      for (std::size_t w = 0; w < row.size(); ++w) row[w] &= above[w];
    }
  return allowed;
}

// Column tops of everything there, wide enough for the holder.
void PocketBuilder::start_column_tops() {
  reach_ = reach_offsets(model_, h_);
  const int R = int(std::floor(model_.max_radius / h_)) + 1;
  tops_box_ = {{work_.lo.x - R, work_.lo.y - R, std::min(work_.lo.z, all_.lo.z)}, {work_.hi.x + R, work_.hi.y + R, all_.hi.z}};
  untouchable_tops_ = column_top_indices(untouchable_, tops_box_);
  tops_ = untouchable_tops_;
  refresh_tops(tops_box_);
}

bool PocketBuilder::finishes_walls() const {
  return options_.finish_walls && options_.design && !options_.design->empty() && tool_.type == config::ToolType::Flat;
}

// The layers where material a deposit laid borders the region the action may remove
// (within 1.5 voxels in the layer): levels every step-down from the highest down to the
// lowest, and the box of those cells.
PocketBuilder::LaidWalls PocketBuilder::laid_walls(const Solid& laid, const Solid& region) const {
  LaidWalls out;
  const IndexBox rb = region.bounding_box();
  const IndexBox b = geometry::box_intersection(
      laid.bounding_box(), {{rb.lo.x - 2, rb.lo.y - 2, rb.lo.z}, {rb.hi.x + 2, rb.hi.y + 2, rb.hi.z}});
  if (b.empty()) return out;
  const IndexBox window{{b.lo.x - 2, b.lo.y - 2, b.lo.z}, {b.hi.x + 2, b.hi.y + 2, b.hi.z}};
  for (int k = b.lo.z; k < b.hi.z; ++k) {
    SliceMask beside = slice_of(laid, k, window);
    if (beside.empty()) continue;
    beside &= grow_by_disc(slice_of(region, k, window), 1.5);
    const CellBox cells = cell_bounds(beside);
    if (!cells.empty()) out.box = geometry::box_union(out.box, {{cells.x0, cells.y0, k}, {cells.x1, cells.y1, k + 1}});
  }
  if (out.box.empty()) return out;
  for (int k = out.box.hi.z - 1; k > out.box.lo.z; k -= down_) out.levels.insert(k);
  out.levels.insert(out.box.lo.z);
  return out;
}

// The tops of laid material under a floor of the design the tool faces (the region over
// them): per level, the layer above them with its tip at the floor's height (set in
// level_heights_ where no cutting level has one), the cells to skim. A bead stands above
// the floor by up to its head's accuracy, which no voxel shows.
std::map<int, SliceMask> PocketBuilder::laid_floors(const Solid& laid, const Solid& region) {
  std::map<int, SliceMask> out;
  const IndexBox b = geometry::box_intersection(laid.bounding_box(), {{work_.lo.x, work_.lo.y, laid.bounding_box().lo.z},
                                                                      {work_.hi.x, work_.hi.y, laid.bounding_box().hi.z}});
  for (int k = b.lo.z; k < b.hi.z; ++k) {
    SliceMask top = slice_of(laid, k, work_);
    if (top.empty()) continue;
    top &= slice_of(region, k + 1, work_);
    if (top.empty()) continue;
    const double floor = floor_height(k + 1);
    if (std::isinf(floor)) continue;
    level_heights_.emplace(k + 1, floor);
    out.emplace(k + 1, std::move(top));
  }
  return out;
}

// Top-down every `down` voxels from the top, plus every floor of the ROI: material with
// something that must remain under it before the next level down (a step-down at most),
// where the tip cannot go lower. Material over air needs no level of its own: the next
// level down reaches under it and the flutes take it from the side (the cutter's discs
// over its tip), as a scalloped deposit's wall is milled in step-downs, not layer by layer.
PocketBuilder::Levels PocketBuilder::cutting_levels() const {
  const IndexBox rb = remaining_.bounding_box();
  Levels levels;
  for (int k = rb.hi.z - down_; k > rb.lo.z; k -= down_) levels.insert(k);
  levels.insert(rb.lo.z);
  std::vector<std::uint64_t> held;  // per word of a row: something that stays within a step-down below
  const bool anything_held = !untouchable_.empty();  // a whole-grid count: once, not per row
  for (int z = rb.lo.z + 1; z < rb.hi.z; ++z) {
    bool floor_here = false;
    for (int y = rb.lo.y; y < rb.hi.y && !floor_here; ++y) {
      const auto now = remaining_.row(y, z), below = remaining_.row(y, z - 1);
      held.assign(now.size(), 0);
      for (int d = 1; d <= down_ && anything_held; ++d) held_rows(y, z - d, held);
      for (std::size_t w = 0; w < now.size(); ++w)
        if (now[w] & ~below[w] & held[w]) {
          floor_here = true;
          break;
        }
    }
    if (floor_here) levels.insert(z);
  }
  return levels;
}

// The highest of the design's floors in (centre - h, centre] of layer k's voxels, where a
// flat cutter's tip at level k takes the same voxels; -infinity when none.
double PocketBuilder::floor_height(int k) const {
  const double c = centre_z(k);
  double z = -kInf;
  for (const geometry::Triangle& f : options_.floors)
    if (f[0].z > c - h_ + 1e-6 && f[0].z <= c + 1e-9) z = std::max(z, f[0].z);
  return z;
}

// A flat cutter's tip anywhere in (centre - h, centre] of level k's voxels takes the same
// voxels (none below: their centres lie under its flat bottom), so it goes to where the
// part's face is: the highest floor of the design in that range, or, with nothing to keep
// anywhere under the level, the bottom of its voxels (the start stock's face). A ball or
// bull nose would sweep wider discs lower down: it stays at the centre.
std::map<int, double> PocketBuilder::exact_heights(const Levels& levels) const {
  std::map<int, double> out;
  if (tool_.type != config::ToolType::Flat) return out;
  constexpr double kSlack = 1e-9;  // mm
  for (const int k : levels) {
    const double c = centre_z(k);
    double z = floor_height(k);
    if (std::isinf(z) && (k - 1 < untouchable_.storage_box().lo.z || k - 1 >= untouchable_.storage_box().hi.z ||
                          slice_of(untouchable_, k - 1, work_).empty()))
      z = c - h_ / 2;
    if (!std::isinf(z) && z < c - kSlack) out[k] = z;
  }
  return out;
}

// ORs the untouchable voxels of row (y, z) into `held`, on remaining_'s words (words
// are whole 64-voxel runs of X in every solid, so they line up).
void PocketBuilder::held_rows(int y, int z, std::vector<std::uint64_t>& held) const {
  const IndexBox mine = remaining_.storage_box(), theirs = untouchable_.storage_box();
  if (y < theirs.lo.y || y >= theirs.hi.y || z < theirs.lo.z || z >= theirs.hi.z) return;
  const auto row = untouchable_.row(y, z);
  const int shift = (mine.lo.x - theirs.lo.x) / 64;
  for (std::size_t w = 0; w < held.size(); ++w) {
    const int u = int(w) + shift;
    if (u >= 0 && u < int(row.size())) held[w] |= row[std::size_t(u)];
  }
}

// The allowed tips at level k less those whose shank or holder would meet material still
// there (material the round tool left above, out of its reach): each body disc grown
// around the columns whose material reaches the disc's lowest level (for the holder,
// which never ends, exact; for the shank, conservative).
SliceMask PocketBuilder::usable_tips(const Solid& allowed, int k) const {
  SliceMask usable = slice_of(allowed, k, work_);
  if (remaining_.bounding_box().hi.z - 1 < k + model_.body_first_level) return usable;
  const std::vector<int> top = column_top_indices(remaining_, work_);
  const int nx = work_.hi.x - work_.lo.x;
  for (const auto& [radius, from] : model_.body_discs) {
    SliceMask reached(work_.lo.x, work_.lo.y, nx, work_.hi.y - work_.lo.y);
    for (int y = work_.lo.y; y < work_.hi.y; ++y)
      for (int x = work_.lo.x; x < work_.hi.x; ++x)
        if (top[std::size_t(y - work_.lo.y) * std::size_t(nx) + std::size_t(x - work_.lo.x)] >= k + from) reached.set(x, y);
    if (!reached.empty()) usable = usable.without(grow_by_disc(reached, radius));
  }
  return usable;
}

// The usable tips whose cutter meets material still there: each disc of the cutter grown
// around the material in the layers it reaches.
SliceMask PocketBuilder::useful_tips(const SliceMask& usable, int k) const {
  SliceMask useful(work_.lo.x, work_.lo.y, work_.hi.x - work_.lo.x, work_.hi.y - work_.lo.y);
  for (const auto& [radius, levels] : model_.cutter_discs) {
    SliceMask material = slice_of(remaining_, k + levels.front(), work_);
    for (std::size_t i = 1; i < levels.size(); ++i) material |= slice_of(remaining_, k + levels[i], work_);
    if (!material.empty()) useful |= grow_by_disc(material, radius);
  }
  useful &= usable;
  return useful;
}

void PocketBuilder::clear_level(const SliceMask& useful, const SliceMask& usable, int k, int level_number) {
  air_cache_.clear();
  level_ = k;
  pending_comment_ = "level " + std::to_string(level_number) + " z=" + mm(level_z(k));
  if (options_.strategy == PocketStrategy::Zigzag) {
    const bool alternate = options_.raster == PocketRaster::Alternate;
    const bool along_x = options_.raster == PocketRaster::AlongX || (alternate && level_number % 2 == 1);
    cut_paths(zigzag_rows(useful, along_x, over_), k, usable);
    if (options_.wall_pass == WallPass::Contour) cut_paths(chain_paths(boundary_cells(useful), useful, usable), k, usable);
  } else {
    // Rings close enough that every cell between two is within the cutter's reach, cut
    // from the innermost out.
    const double ring = std::clamp(std::min(step_over_, model_.cutter_radius - 1.5 * h_), h_, std::max(step_over_, h_));
    std::vector<std::vector<CellPath>> rings;
    for (int i = 0;; ++i) {
      const SliceMask inner = i == 0 ? useful : shrink_by_disc(useful, i * ring / h_);
      if (inner.empty()) break;
      rings.push_back(chain_paths(boundary_cells(inner), inner, usable));
    }
    for (auto it = rings.rbegin(); it != rings.rend(); ++it) cut_paths(*it, k, usable);
  }
  retract();
}

void PocketBuilder::report_what_stays() {
  const std::int64_t left = remaining_.voxel_count();
  if (left > 0) {
    const IndexBox lb = remaining_.bounding_box();
    const geometry::Box3 mmbox = lattice_.extent(lb);
    path_.warnings.push_back(mm(double(left) * h_ * h_ * h_) + " mm^3 (" + std::to_string(left) +
                             " voxels) of the region stay: the tool cannot reach them without touching what must "
                             "remain, within x " + mm(mmbox.min.x) + ".." + mm(mmbox.max.x) + ", y " + mm(mmbox.min.y) +
                             ".." + mm(mmbox.max.y) + ", z " + mm(mmbox.min.z) + ".." + mm(mmbox.max.z) +
                             " mm (work frame)");
  }
  if (finish_skipped_ > 0 || finish_skipped_length_ > 0.5)
    path_.warnings.push_back("wall finishing: " + mm(finish_skipped_length_) + " mm of the walls' contours not finished (" +
                             std::to_string(finish_skipped_) +
                             " passes with no lead-in or lead-out from air); the roughing left up to a voxel there");
  if (skipped_entries_ > 0)
    path_.warnings.push_back(std::to_string(skipped_entries_) +
                             " passes skipped: the shank or holder would meet material on the way down to them");
  // Nothing of the region reached at all: the action cannot be made (a defect). What a
  // started path leaves (corners a round tool cannot reach) is judged by the part as built
  // against the tolerance (validation/), so it stays a warning.
  if (!started_ && left > 0) {
    const geometry::Box3 b = lattice_.extent(remaining_.bounding_box());
    path_.defects.push_back({"unreachable", "no tool position reaches the region without touching what must remain",
                             {(b.min.x + b.max.x) / 2, (b.min.y + b.max.y) / 2, (b.min.z + b.max.z) / 2}});
  } else if (!started_) {
    path_.warnings.push_back("no tool position reaches the region without touching what must remain");
  }
}

Toolpath& PocketBuilder::run(const Solid& roi, const Solid& keep, const Solid& stock, const Solid* design,
                             const Solid* finish_region, const Solid* laid) {
  lattice_ = roi.lattice();
  h_ = lattice_.voxel_size;
  model_ = make_tool(tool_, h_);
  use_step_sizes();
  const bool material = take_material(roi, keep, stock);
  const Solid& region = finish_region ? *finish_region : roi;
  const LaidWalls walls = laid && finishes_walls() ? laid_walls(*laid, region) : LaidWalls{};
  if (!material && walls.levels.empty()) {
    path_.warnings.push_back("nothing to remove: the region of influence holds no material");
    return path_;
  }
  const IndexBox rb = geometry::box_union(remaining_.bounding_box(), walls.box);
  const int rc = int(std::ceil(model_.cutter_radius / h_));
  const int margin = 2 * rc + 4;
  work_ = {{rb.lo.x - margin, rb.lo.y - margin, rb.lo.z}, {rb.hi.x + margin, rb.hi.y + margin, all_.hi.z + 1}};
  start_column_tops();
  const Levels cutting = material ? cutting_levels() : Levels{};
  level_heights_ = exact_heights(cutting);
  const std::map<int, SliceMask> skims = laid && finishes_walls() ? laid_floors(*laid, region) : std::map<int, SliceMask>{};
  const Solid allowed = material || !skims.empty() ? allowed_tips() : Solid(lattice_, {});
  Levels levels = cutting;
  levels.insert(walls.levels.begin(), walls.levels.end());
  for (const auto& [k, cells] : skims) levels.insert(k);
  // The faces an action finishes are those next to what it may remove, also where an
  // earlier action left less than a voxel on them.
  start_finishing(region, design);
  start_surface_finishing(region, design);
  int level_number = 0;
  int k_above = rb.hi.z;  // the ROI's layers [k, k_above) are level k's to remove
  double z_above = lattice_.origin.z + rb.hi.z * h_;
  for (const int k : levels) {
    if (remaining_.empty() && !finishing_) break;
    // Levels of the laid walls alone are finished, not roughed; the tops of laid material
    // under a floor are skimmed at the floor's height.
    const bool roughed = cutting.count(k) > 0 && !remaining_.empty();
    const auto skim = skims.find(k);
    std::optional<TipKeepOut> keep_out;
    if (finishing_) keep_out = keep_out_at(level_z(k));
    if (roughed || skim != skims.end()) {
      SliceMask usable = usable_tips(allowed, k);
      if (drop_) usable = usable.without(under_surface(level_z(k)));
      // The roughing keeps the cutter off the design's real surface, not only off the
      // voxel centres; the finishing passes take what that leaves.
      if (keep_out && !keep_out->empty()) usable = usable.without(cells_in(keep_out->grown(rough_margin_)));
      SliceMask useful = roughed ? useful_tips(usable, k) : usable.without(usable);
      if (skim != skims.end()) {
        SliceMask over = grow_by_disc(skim->second, model_.cutter_radius / h_);
        over &= usable;
        useful |= over;
      }
      if (!useful.empty()) clear_level(useful, usable, k, ++level_number);
    }
    if (keep_out) {
      finish_walls(*keep_out, k, k_above, level_z(k));
      // Walls that end at a face between this level and the one above, from that face.
      for (const double zf : face_heights_)
        if (zf > level_z(k) + 1e-6 && zf < z_above - 1e-6) finish_walls(keep_out_at(zf), k, k_above, zf);
    }
    k_above = k;
    z_above = level_z(k);
  }
  if (finishing_) finish_walls_below(k_above, z_above);
  finish_surfaces();
  if (started_ && at_.z < safe_z_) move(MoveKind::Rapid, {at_.x, at_.y, safe_z_}, 0, false);
  report_what_stays();
  return path_;
}

}  // namespace pocket

Toolpath pocket_path(const geometry::Solid& roi_part, const geometry::Solid& keep_part, const geometry::Solid& stock_part,
                     const config::CuttingTool& tool_in, const config::Setup& setup, const PocketOptions& options) {
  using geometry::Solid;
  for (const Solid* s : {&keep_part, &stock_part})
    if (!s->empty() && !(s->lattice() == roi_part.lattice()))
      throw std::invalid_argument("pocket_path: the ROI, keep and stock solids are on different lattices");
  config::CuttingTool tool;
  try {
    tool = instruments::with_defaults(tool_in);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("pocket_path: ") + e.what());
  }
  Toolpath path;
  path.process = Process::Milling;
  path.instrument = tool.name.empty() ? "T" + std::to_string(tool.number) : tool.name;
  path.tool_number = tool.number;
  path.setup = setup.name;
  const Solid roi = part_to_work(roi_part, setup.approach);
  const Solid keep = keep_part.empty() ? Solid(roi.lattice(), {}) : part_to_work(keep_part, setup.approach);
  const Solid stock = stock_part.empty() ? Solid(roi.lattice(), {}) : part_to_work(stock_part, setup.approach);
  std::optional<Solid> design;
  const bool exact = tool.type == config::ToolType::Flat ? options.finish_walls : options.finish_surfaces;
  if (options.design_voxels && options.design && !options.design->empty() && exact) {
    if (!(options.design_voxels->lattice() == roi_part.lattice()))
      throw std::invalid_argument("pocket_path: the design's voxels are on another lattice than the ROI");
    design = part_to_work(*options.design_voxels, setup.approach);
  }
  std::optional<Solid> finish_region;
  if (design && options.finish_region) {
    if (!(options.finish_region->lattice() == roi_part.lattice()))
      throw std::invalid_argument("pocket_path: the finishing region is on another lattice than the ROI");
    finish_region = part_to_work(*options.finish_region, setup.approach);
  }
  std::optional<Solid> laid;
  if (design && options.laid && !options.laid->empty()) {
    if (!(options.laid->lattice() == roi_part.lattice()))
      throw std::invalid_argument("pocket_path: the laid material is on another lattice than the ROI");
    laid = part_to_work(*options.laid, setup.approach);
  }
  pocket::PocketBuilder builder(tool, options, path);
  builder.run(roi, keep, stock, design ? &*design : nullptr, finish_region ? &*finish_region : nullptr,
              laid ? &*laid : nullptr);
  return path;
}

}  // namespace hybridctl::toolpaths
