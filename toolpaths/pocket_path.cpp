#include "toolpaths/pocket_path.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <optional>
#include <map>
#include <set>
#include <stdexcept>
#include <string>

#include "toolpaths/setup_frame.hpp"
#include "toolpaths/slices.hpp"
#include "geometry/morphology.hpp"

namespace hybridctl::toolpaths {
namespace {

using geometry::AxialBody;
using geometry::AxialSection;
using geometry::IndexBox;
using geometry::Solid;
using geometry::Vec3;

constexpr double kInf = std::numeric_limits<double>::infinity();
// Heights are compared with this slack (mm): a tool tip this close above a voxel centre
// still counts as touching it.
constexpr double kHeightSlack = 1e-6;
// Samples per voxel when the tool's radius profile is scanned along its axis.
constexpr int kProfileSamplesPerVoxel = 32;

std::string mm(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f", v);
  return buf;
}

// ---------------------------------------------------------------------------------------
// The tool, tip at the origin, axis +Z (work frame).

// The machine file's documented defaults for values a hand-made CuttingTool leaves at 0.
config::CuttingTool with_defaults(config::CuttingTool t) {
  if (!(t.diameter > 0)) throw std::invalid_argument("pocket_path: tool T" + std::to_string(t.number) + " has no diameter");
  if (!(t.flute_length > 0)) t.flute_length = 3 * t.diameter;
  if (!(t.shank.diameter > 0)) t.shank.diameter = t.diameter;
  if (!(t.shank.length > 0)) t.shank.length = 2 * t.diameter;
  if (!(t.holder.diameter > 0)) t.holder.diameter = 50;
  if (!(t.holder.length > 0)) t.holder.length = 60;
  if (!(t.step_down > 0)) t.step_down = 0.5 * t.diameter;
  if (!(t.step_over > 0)) t.step_over = 0.4 * t.diameter;
  if (t.type == config::ToolType::Ball) t.corner_radius = t.diameter / 2;
  if (t.type == config::ToolType::Bull && !(t.corner_radius > 0 && t.corner_radius < t.diameter / 2))
    throw std::invalid_argument("pocket_path: bull tool T" + std::to_string(t.number) + " needs 0 < corner_radius < diameter/2");
  if (t.type == config::ToolType::Flat) t.corner_radius = 0;
  if (!(t.feed > 0)) t.feed = 1000;
  if (!(t.plunge_feed > 0)) t.plunge_feed = 300;
  return t;
}

double profile_sq(const std::vector<AxialSection>& sections, double dz) {
  double best = -1;
  for (const AxialSection& s : sections) best = std::max(best, s.radius_squared_at(dz));
  return best;
}

// A body whose level t (offset t * h along the axis) has the largest radius the exact
// sections reach anywhere in [(t - 1) h, t h]. Checked at a tip on a voxel-centre height,
// it covers every tip height up to one voxel above it: tips between levels (ramps,
// plunges, retracts) are then as safe as tips on them.
AxialBody guard_body(const std::vector<AxialSection>& sections, double h) {
  double finite_end = 0, tail_from = kInf, tail_radius = -1;
  for (const AxialSection& s : sections) {
    if (std::isinf(s.to)) {
      tail_from = std::min(tail_from, s.from);
      tail_radius = std::max(tail_radius, s.radius);
    } else {
      finite_end = std::max(finite_end, s.to);
    }
  }
  const double last = std::max(finite_end, std::isinf(tail_from) ? 0.0 : tail_from);
  const int levels = int(std::ceil(last / h)) + 2;
  AxialBody body{{geometry::Axis::Z, +1}, {}};
  for (int t = 0; t < levels; ++t) {
    const double lo = std::max(0.0, (t - 1) * h), hi = t * h;
    std::vector<double> samples;
    for (int i = 0; i <= kProfileSamplesPerVoxel; ++i) samples.push_back(lo + (hi - lo) * i / kProfileSamplesPerVoxel);
    for (const AxialSection& s : sections)
      for (double v : {s.from, s.to, s.centre})
        if (v >= lo && v <= hi) samples.push_back(v);
    double r2 = -1;
    for (double z : samples) r2 = std::max(r2, profile_sq(sections, z));
    if (r2 >= 0) body.sections.push_back({AxialSection::Kind::Cylinder, t * h - h / 4, t * h + h / 4, std::sqrt(r2), 0, 0});
  }
  if (tail_radius >= 0) body.sections.push_back({AxialSection::Kind::Cylinder, levels * h, kInf, tail_radius, 0, 0});
  return body;
}

struct ToolModel {
  std::vector<AxialSection> cutting, body;
  AxialBody whole_guard;  // cutter + body, conservative: what must not touch `keep`
  AxialBody body_guard;   // body alone, conservative: what must not touch material
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
};

ToolModel make_tool(const config::CuttingTool& tool, double h) {
  ToolModel m;
  const double r = tool.diameter / 2, flute = tool.flute_length;
  switch (tool.type) {
    case config::ToolType::Flat: m.cutting.push_back({AxialSection::Kind::Cylinder, 0, flute, r, 0, 0}); break;
    case config::ToolType::Ball:
      m.cutting.push_back({AxialSection::Kind::Sphere, 0, r, r, r, 0});
      m.cutting.push_back({AxialSection::Kind::Cylinder, r, flute, r, 0, 0});
      break;
    case config::ToolType::Bull: {
      const double rc = tool.corner_radius;
      m.cutting.push_back({AxialSection::Kind::Torus, 0, rc, rc, rc, r - rc});
      m.cutting.push_back({AxialSection::Kind::Cylinder, rc, flute, r, 0, 0});
      break;
    }
  }
  // As planner/machine_primitives.cpp tool_instrument: shank, then the holder, then the
  // spindle: the body never ends.
  const double shank_end = flute + tool.shank.length;
  m.body.push_back({AxialSection::Kind::Cylinder, flute, shank_end, tool.shank.diameter / 2, 0, 0});
  m.body.push_back({AxialSection::Kind::Cylinder, shank_end, kInf, tool.holder.diameter / 2, 0, 0});
  std::vector<AxialSection> whole = m.cutting;
  whole.insert(whole.end(), m.body.begin(), m.body.end());
  m.whole_guard = guard_body(whole, h);
  m.body_guard = guard_body(m.body, h);
  m.cutter_radius = r;
  m.max_radius = std::max({r, tool.shank.diameter / 2, tool.holder.diameter / 2});
  m.body_first_level = int(std::floor(flute / h));
  for (const AxialSection& g : m.body_guard.sections) {
    const double radius = g.radius / h;
    const int from = int(std::lround(std::isinf(g.to) ? g.from / h : (g.from + g.to) / 2 / h));
    auto it = std::find_if(m.body_discs.begin(), m.body_discs.end(), [&](const auto& d) { return d.first == radius; });
    if (it == m.body_discs.end()) m.body_discs.push_back({radius, from});
    else it->second = std::min(it->second, from);
  }
  for (int t = 0; t <= int(std::floor(flute / h + 1e-9)); ++t) {
    const double r2 = profile_sq(m.cutting, t * h);
    if (r2 < 0) continue;
    const double radius = std::sqrt(r2) / h;
    auto it = std::find_if(m.cutter_discs.begin(), m.cutter_discs.end(), [&](const auto& d) { return d.first == radius; });
    if (it == m.cutter_discs.end()) m.cutter_discs.push_back({radius, {t}});
    else it->second.push_back(t);
  }
  double widest = -1;
  for (int i = 0; i <= int(std::ceil((shank_end + h) / h)) * kProfileSamplesPerVoxel; ++i) {
    const double r2 = profile_sq(whole, i * h / kProfileSamplesPerVoxel);
    if (r2 < widest - 1e-9) m.widening = false;
    widest = std::max(widest, r2);
  }
  return m;
}

// For a column at (dx, dy) voxels from the tool axis: the lowest height above the tip
// (mm) at which the tool (or its cutter) reaches that far out; infinity when never. A
// tool moving vertically down to tip height z sweeps exactly the heights >= z + zmin.
struct ReachOffset {
  int dx = 0, dy = 0;
  double zmin_whole = kInf, zmin_cutter = kInf, zmin_body = kInf;
};

std::vector<ReachOffset> reach_offsets(const ToolModel& m, double h) {
  // The running maximum of the squared radius along the axis, sampled finely; the first
  // height where it reaches rho^2, minus one sample (rounded towards the tip: safe).
  const double step = h / kProfileSamplesPerVoxel;
  double finite_end = 0;
  for (const auto* secs : {&m.cutting, &m.body})
    for (const AxialSection& s : *secs) finite_end = std::max(finite_end, std::isinf(s.to) ? s.from : s.to);
  const int n = int(std::ceil((finite_end + h) / step)) + 1;
  auto running = [&](const std::vector<AxialSection>& secs) {
    std::vector<double> r(std::size_t(n), -1);
    double best = -1;
    for (int i = 0; i < n; ++i) {
      best = std::max(best, profile_sq(secs, i * step));
      r[std::size_t(i)] = best;
    }
    return r;
  };
  std::vector<AxialSection> whole = m.cutting;
  whole.insert(whole.end(), m.body.begin(), m.body.end());
  const std::vector<double> run_whole = running(whole), run_cut = running(m.cutting), run_body = running(m.body);
  auto first_reach = [&](const std::vector<double>& run, double rho2) {
    const auto it = std::lower_bound(run.begin(), run.end(), rho2 - 1e-9);
    if (it == run.end()) return kInf;
    return std::max(0.0, double(it - run.begin() - 1) * step);
  };
  const int R = int(std::floor(m.max_radius / h));
  std::vector<ReachOffset> out;
  for (int dy = -R; dy <= R; ++dy)
    for (int dx = -R; dx <= R; ++dx) {
      const double rho2 = double(dx * dx + dy * dy) * h * h;
      ReachOffset o{dx, dy, first_reach(run_whole, rho2), first_reach(run_cut, rho2), first_reach(run_body, rho2)};
      if (!std::isinf(o.zmin_whole)) out.push_back(o);
    }
  return out;
}

// ---------------------------------------------------------------------------------------
// Paths of one level, as cells (voxel columns) joined by axis-aligned legs.

struct CellPath {
  std::vector<Cell> points;  // consecutive points share a row or a column
  bool closed = false;       // first == last
};

int manhattan(Cell a, Cell b) { return std::abs(a.x - b.x) + std::abs(a.y - b.y); }

Cell unit_towards(Cell a, Cell b) {
  return {b.x > a.x ? 1 : b.x < a.x ? -1 : 0, b.y > a.y ? 1 : b.y < a.y ? -1 : 0};
}

// Calls fn for every cell of the axis-aligned leg a -> b, a and b included.
template <class Fn>
void for_leg_cells(Cell a, Cell b, Fn fn) {
  const Cell d = unit_towards(a, b);
  Cell c = a;
  fn(c);
  while (!(c == b)) {
    c = {c.x + d.x, c.y + d.y};
    fn(c);
  }
}

bool leg_inside(Cell a, Cell b, const SliceMask& usable) {
  if (a.x != b.x && a.y != b.y) return false;
  bool ok = true;
  for_leg_cells(a, b, [&](Cell c) { ok = ok && usable.at(c); });
  return ok;
}

// A link a -> b inside `usable`: straight, or two legs through a corner.
std::optional<std::vector<Cell>> link_cells(Cell a, Cell b, const SliceMask& usable) {
  if (a == b) return std::vector<Cell>{};
  if ((a.x == b.x || a.y == b.y) && leg_inside(a, b, usable)) return std::vector<Cell>{b};
  for (Cell corner : {Cell{b.x, a.y}, Cell{a.x, b.y}})
    if (leg_inside(a, corner, usable) && leg_inside(corner, b, usable)) return std::vector<Cell>{corner, b};
  return std::nullopt;
}

// Drops middle points of straight runs.
std::vector<Cell> simplify(const std::vector<Cell>& pts) {
  std::vector<Cell> out;
  for (const Cell& c : pts) {
    if (!out.empty() && out.back() == c) continue;
    if (out.size() >= 2) {
      const Cell a = out[out.size() - 2], b = out.back();
      if ((a.x == b.x && b.x == c.x) || (a.y == b.y && b.y == c.y)) {
        const Cell d1 = unit_towards(a, b), d2 = unit_towards(b, c);
        if (d1 == d2) out.pop_back();
      }
    }
    out.push_back(c);
  }
  return out;
}

std::vector<CellPath> zigzag_rows(const SliceMask& region, bool along_x, int spacing) {
  std::vector<CellPath> out;
  const CellBox b = cell_bounds(region);
  if (b.empty()) return out;
  const int lo = along_x ? b.y0 : b.x0, hi = along_x ? b.y1 : b.x1;
  std::vector<int> rows;
  for (int v = lo; v < hi; v += spacing) rows.push_back(v);
  if (rows.back() != hi - 1) rows.push_back(hi - 1);
  for (int v : rows) {
    const std::vector<Run> runs = along_x ? row_runs(region, v) : column_runs(region, v);
    for (const Run& r : runs) {
      CellPath p;
      if (along_x) p.points = {{r.x_begin, v}, {r.x_end - 1, v}};
      else p.points = {{v, r.x_begin}, {v, r.x_end - 1}};
      if (p.points[0] == p.points[1]) p.points.pop_back();
      out.push_back(std::move(p));
    }
  }
  return out;
}

// Boundary chains (8-connected) as axis-aligned paths: a diagonal step goes round the
// corner cell that is usable (preferring one in `region`); with neither, the chain splits.
std::vector<CellPath> chain_paths(const SliceMask& cells, const SliceMask& region, const SliceMask& usable) {
  std::vector<CellPath> out;
  for (const auto& chain : trace_chains(cells)) {
    CellPath p;
    auto flush = [&]() {
      if (!p.points.empty()) {
        p.points = simplify(p.points);
        p.closed = p.points.size() > 2 && p.points.front() == p.points.back();
        out.push_back(std::move(p));
      }
      p = CellPath{};
    };
    for (std::size_t i = 0; i < chain.size(); ++i) {
      const Cell c = chain[i];
      if (!p.points.empty()) {
        const Cell a = p.points.back();
        if (a.x != c.x && a.y != c.y) {
          const Cell k1{c.x, a.y}, k2{a.x, c.y};
          const bool u1 = usable.at(k1), u2 = usable.at(k2);
          if (u1 && (region.at(k1) || !u2)) p.points.push_back(k1);
          else if (u2) p.points.push_back(k2);
          else flush();
        }
      }
      p.points.push_back(c);
    }
    flush();
  }
  return out;
}

// A way to start one of the paths still to cut: from its front (mode 0), from its back
// (mode 1, the path runs backwards), or for a closed path from its waypoint `at` (mode 2).
struct Candidate {
  std::size_t path = 0;
  int mode = 0;
  std::size_t at = 0;
  int distance = 0;
};

// Every way to start a path, nearest to `from` first.
std::vector<Candidate> candidates(const std::vector<CellPath>& todo, Cell from) {
  std::vector<Candidate> out;
  for (std::size_t i = 0; i < todo.size(); ++i) {
    const CellPath& p = todo[i];
    if (p.closed) {
      for (std::size_t j = 0; j + 1 < p.points.size(); ++j) out.push_back({i, 2, j, manhattan(from, p.points[j])});
    } else {
      out.push_back({i, 0, 0, manhattan(from, p.points.front())});
      if (p.points.size() > 1) out.push_back({i, 1, 0, manhattan(from, p.points.back())});
    }
  }
  std::stable_sort(out.begin(), out.end(), [](const Candidate& a, const Candidate& b) { return a.distance < b.distance; });
  return out;
}

CellPath oriented(const CellPath& path, const Candidate& c) {
  CellPath p = path;
  if (c.mode == 1) std::reverse(p.points.begin(), p.points.end());
  if (c.mode == 2 && c.at > 0) {
    std::vector<Cell> loop(p.points.begin(), p.points.end() - 1);
    std::rotate(loop.begin(), loop.begin() + std::ptrdiff_t(c.at), loop.end());
    loop.push_back(loop.front());
    p.points = simplify(loop);
  }
  return p;
}

// How many of the nearest starts are tried for a feed link, and for an entry from air,
// before retracting or ramping.
constexpr std::size_t kLinkCandidates = 8;
constexpr std::size_t kEntryCandidates = 12;

// ---------------------------------------------------------------------------------------

class PocketBuilder {
 public:
  PocketBuilder(const config::CuttingTool& tool, const PocketOptions& options, Toolpath& path)
      : tool_(tool), options_(options), path_(path) {}

  Toolpath& run(const Solid& roi, const Solid& keep, const Solid& stock);

 private:
  double centre_z(int k) const { return lattice_.origin.z + (k + 0.5) * h_; }
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
  bool enter(const CellPath& p, int k, const SliceMask& usable);
  // Where the tool can come straight down in air and reach the start of `p` at level k:
  // the start itself, or a cell before it on the line of its first leg (a lead-in).
  std::optional<Cell> air_entry(const CellPath& p, int k, const SliceMask& usable);
  bool in_air(Cell c, int k);
  void cut_paths(std::vector<CellPath> todo, int k, const SliceMask& usable);
  Cell current_cell() const {
    return {int(std::floor((at_.x - lattice_.origin.x) / h_)), int(std::floor((at_.y - lattice_.origin.y) / h_))};
  }
  void stamp_run(int k);

  config::CuttingTool tool_;
  PocketOptions options_;
  Toolpath& path_;
  geometry::Lattice lattice_;
  double h_ = 1;
  ToolModel model_;
  std::vector<ReachOffset> reach_;
  IndexBox work_;  // tip domain
  Solid remaining_, untouchable_;
  IndexBox tops_box_;
  std::vector<int> tops_, untouchable_tops_;
  double safe_z_ = 0;
  Vec3 at_{};
  bool started_ = false;
  bool at_level_ = false;
  std::vector<Cell> run_cells_;
  std::string pending_comment_;
  std::map<std::pair<int, int>, bool> air_cache_;  // per level, until the next removal
  int plunges_into_material_ = 0, skipped_entries_ = 0;
};

void PocketBuilder::move(MoveKind kind, Vec3 to, double feed, bool cutting, std::string comment) {
  if (to == at_ && started_) return;
  PathMove m;
  m.kind = kind;
  m.to = to;
  m.feed = kind == MoveKind::Rapid ? 0 : feed;
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
  for (const auto& [radius, levels] : model_.cutter_discs) {
    const SliceMask swept = grow_by_disc(tips, radius);
    for (int y = swept.y0(); y < swept.y0() + swept.ny(); ++y)
      for (int x = swept.x0(); x < swept.x0() + swept.nx(); ++x) {
        if (!swept.at(x, y)) continue;
        for (const int t : levels) {
          const geometry::Index3 v{x, y, k + t};
          if (storage.contains(v) && remaining_.contains(v)) remaining_.set(v, false);
        }
      }
  }
  refresh_tops({{x0 - R, y0 - R, 0}, {x1 + 1 + R, y1 + 1 + R, 1}});
}

void PocketBuilder::retract() {
  if (!at_level_) return;
  const int k = int(std::floor((at_.z - lattice_.origin.z) / h_));
  stamp_run(k);
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

bool PocketBuilder::in_air(Cell c, int k) {
  const auto key = std::pair<int, int>{c.x, c.y};
  if (const auto it = air_cache_.find(key); it != air_cache_.end()) return it->second;
  const bool air = contact_height(c, Part::Whole) < centre_z(k) - kHeightSlack;
  air_cache_[key] = air;
  return air;
}

std::optional<Cell> PocketBuilder::air_entry(const CellPath& p, int k, const SliceMask& usable) {
  const Cell b = p.points.front();
  if (in_air(b, k)) return b;
  std::vector<Cell> dirs;
  if (p.points.size() >= 2) {
    const Cell d = unit_towards(p.points[0], p.points[1]);
    dirs.push_back({-d.x, -d.y});
  } else {
    dirs = {{-1, 0}, {1, 0}, {0, -1}, {0, 1}};
  }
  // Far enough to get the cutter clear of the material at the start.
  const int lead_max = int(std::ceil(model_.cutter_radius / h_)) + 3;
  for (const Cell d : dirs)
    for (int i = 1; i <= lead_max; ++i) {
      const Cell a{b.x + i * d.x, b.y + i * d.y};
      if (!usable.at(a)) break;
      if (in_air(a, k)) return a;
    }
  return std::nullopt;
}

void PocketBuilder::cut_paths(std::vector<CellPath> todo, int k, const SliceMask& usable) {
  const double zk = centre_z(k);
  auto take = [&](const Candidate& c) {
    CellPath p = oriented(todo[c.path], c);
    todo[c.path] = std::move(todo.back());
    todo.pop_back();
    return p;
  };
  auto cut_along = [&](const CellPath& p) {
    for (std::size_t i = 1; i < p.points.size(); ++i) {
      for_leg_cells(p.points[i - 1], p.points[i], [&](Cell v) { run_cells_.push_back(v); });
      move(MoveKind::Feed, at_cell(p.points[i], zk), tool_.feed, true);
    }
  };
  while (!todo.empty()) {
    const Cell cur = started_ ? current_cell() : todo.front().points.front();
    const std::vector<Candidate> cands = candidates(todo, cur);
    if (at_level_) {
      // Feed over to the nearest start that a link inside the usable region reaches.
      bool linked = false;
      for (std::size_t i = 0; i < cands.size() && i < kLinkCandidates && !linked; ++i) {
        const CellPath probe = oriented(todo[cands[i].path], cands[i]);
        if (const auto link = link_cells(cur, probe.points.front(), usable)) {
          const CellPath p = take(cands[i]);
          Cell prev = cur;
          for (const Cell& c : *link) {
            for_leg_cells(prev, c, [&](Cell v) { run_cells_.push_back(v); });
            move(MoveKind::Feed, at_cell(c, zk), tool_.feed, true);
            prev = c;
          }
          cut_along(p);
          linked = true;
        }
      }
      if (linked) continue;
      retract();
    }
    // Enter at the nearest start reachable from air, else at the nearest.
    std::size_t pick = 0;
    for (std::size_t i = 0; i < cands.size() && i < kEntryCandidates; ++i)
      if (air_entry(oriented(todo[cands[i].path], cands[i]), k, usable)) {
        pick = i;
        break;
      }
    const CellPath p = take(cands[pick]);
    if (enter(p, k, usable)) cut_along(p);
  }
}

// Gets the tool to the start of `p` at level k from safe_z: a plunge where the way down
// is in air, else a lead-in from air along the first leg, else a ramp along it.
bool PocketBuilder::enter(const CellPath& p, int k, const SliceMask& usable) {
  const double zk = centre_z(k);
  const Cell b = p.points.front();
  auto go_above = [&](Cell c, double stop) {
    const Vec3 top = at_cell(c, safe_z_);
    if (!started_) {
      path_.start = top;
      started_ = true;
      PathMove m;
      m.kind = MoveKind::Rapid;
      m.to = top;
      m.comment = "above the first entry";
      path_.moves.push_back(m);
      at_ = top;
    } else {
      move(MoveKind::Rapid, {top.x, top.y, std::max(at_.z, safe_z_)}, 0, false);
    }
    move(MoveKind::Rapid, at_cell(c, std::min(safe_z_, stop)), 0, false);
  };

  // 1. Air all the way down, at the start or on the line before it: plunge there (and
  // lead in).
  if (const std::optional<Cell> a = air_entry(p, k, usable)) {
    go_above(*a, rapid_stop(*a, zk));
    move(MoveKind::Feed, at_cell(*a, zk), tool_.plunge_feed, false, "plunge in air");
    at_level_ = true;
    for_leg_cells(*a, b, [&](Cell c) { run_cells_.push_back(c); });
    if (!(*a == b)) move(MoveKind::Feed, at_cell(b, zk), tool_.feed, true, "lead-in");
    return true;
  }

  // 3. Ramp down along the first leg (or the longest free row from the start).
  if (contact_height(b, Part::Body) >= zk - kHeightSlack) {
    // The shank or holder would meet material on the way down: no way in here.
    ++skipped_entries_;
    return false;
  }
  const double tan_a = std::tan(std::clamp(options_.ramp_angle_deg, 0.01, 90.0) * std::numbers::pi / 180.0);
  // The ramp starts where the cutter first meets material over the ramp's cells.
  auto ramp_start = [&](Cell d, int m) {
    double z = contact_height(b, Part::Cutter);
    for (int i = 1; i <= m; ++i) z = std::max(z, contact_height({b.x + i * d.x, b.y + i * d.y}, Part::Cutter));
    return std::max(z, zk) + kHeightSlack * 10;
  };
  std::vector<Cell> ramp_dirs;
  if (p.points.size() >= 2) ramp_dirs.push_back(unit_towards(p.points[0], p.points[1]));
  for (Cell d : {Cell{1, 0}, Cell{-1, 0}, Cell{0, 1}, Cell{0, -1}})
    if (ramp_dirs.empty() || !(d == ramp_dirs[0])) ramp_dirs.push_back(d);
  Cell best_dir{0, 0};
  int best_run = 0;
  const double z_guess = ramp_start({0, 0}, 0);
  const int wanted = std::max(1, int(std::ceil((z_guess - zk) / tan_a / h_)));
  for (std::size_t i = 0; i < ramp_dirs.size(); ++i) {
    const Cell d = ramp_dirs[i];
    int run = 0;
    while (run < wanted && usable.at(b.x + (run + 1) * d.x, b.y + (run + 1) * d.y)) ++run;
    // The first leg's direction wins unless another row is much longer.
    if (run > best_run * (i == 0 ? 1 : 2) || (best_run == 0 && run > 0)) {
      best_run = run;
      best_dir = d;
    }
    if (i == 0 && run >= wanted) break;
  }
  const double z_rs = ramp_start(best_dir, best_run);
  go_above(b, rapid_stop(b, z_rs));
  move(MoveKind::Feed, at_cell(b, z_rs), tool_.plunge_feed, false, "down to the material (air)");
  at_level_ = true;
  run_cells_.push_back(b);
  if (best_run == 0 || z_rs - zk <= kHeightSlack * 20) {
    if (z_rs - zk > kHeightSlack * 20) {
      ++plunges_into_material_;
      path_.warnings.push_back("no room to ramp at x=" + mm(at_.x) + " y=" + mm(at_.y) + " z=" + mm(zk) +
                               " (work frame): plunging into material");
    }
    move(MoveKind::Feed, at_cell(b, zk), tool_.plunge_feed, true, "plunge");
    return true;
  }
  const Cell r{b.x + best_run * best_dir.x, b.y + best_run * best_dir.y};
  const double length = best_run * h_;
  int legs = int(std::ceil((z_rs - zk) / tan_a / length - 1e-9));
  legs = std::max(2, legs + (legs % 2));
  const double dz = (z_rs - zk) / legs;
  for (int j = 1; j <= legs; ++j) {
    const Cell target = (j % 2 == 1) ? r : b;
    move(MoveKind::Feed, at_cell(target, j == legs ? zk : z_rs - j * dz), tool_.plunge_feed, true,
         j == 1 ? "ramp " + mm(std::atan((z_rs - zk) / legs / length) * 180 / std::numbers::pi) + " deg" : "");
  }
  return true;
}

Toolpath& PocketBuilder::run(const Solid& roi, const Solid& keep, const Solid& stock) {
  lattice_ = roi.lattice();
  h_ = lattice_.voxel_size;
  model_ = make_tool(tool_, h_);
  double step_down = options_.step_down.value_or(tool_.step_down);
  if (step_down > tool_.flute_length) {
    // Deeper than the flutes, the shank would have to push through what they leave.
    path_.warnings.push_back("step down " + mm(step_down) + " mm is more than the flute length; using " +
                             mm(tool_.flute_length) + " mm");
    step_down = tool_.flute_length;
  }
  const double step_over = options_.step_over.value_or(tool_.step_over);
  if (!(step_down > 0) || !(step_over > 0)) throw std::invalid_argument("pocket_path: step_down and step_over must be > 0");
  const int down = std::max(1, int(std::floor(step_down / h_ + 1e-9)));
  const int over = std::max(1, int(std::floor(step_over / h_ + 1e-9)));

  // What is there: the ROI still to remove, and what must not be touched.
  remaining_ = stock.empty() ? roi : geometry::intersect(roi, stock);
  if (!keep.empty()) remaining_ = geometry::subtract(remaining_, keep);
  untouchable_ = keep.empty() ? Solid(lattice_, {}) : keep;
  if (!stock.empty()) untouchable_ = geometry::unite(untouchable_, geometry::subtract(stock, roi));
  IndexBox all = geometry::box_union(roi.bounding_box(), geometry::box_union(keep.bounding_box(), stock.bounding_box()));
  safe_z_ = (all.empty() ? lattice_.origin.z : lattice_.origin.z + all.hi.z * h_) + options_.safe_clearance;
  path_.safe_z = safe_z_;
  const IndexBox rb = remaining_.bounding_box();
  if (rb.empty()) {
    path_.warnings.push_back("nothing to remove: the region of influence holds no material");
    return path_;
  }

  // The tip domain: around the ROI by the cutter (and room to lead in), from the ROI's
  // bottom to above all material.
  const int rc = int(std::ceil(model_.cutter_radius / h_));
  const int margin = 2 * rc + 4;
  work_ = {{rb.lo.x - margin, rb.lo.y - margin, rb.lo.z}, {rb.hi.x + margin, rb.hi.y + margin, all.hi.z + 1}};

  // Allowed tips: the whole tool clear of `untouchable`, at this height and every height
  // above it (so every vertical move out of an allowed tip is clear as well).
  Solid allowed = untouchable_.empty()
                      ? Solid::filled(lattice_, work_)
                      : geometry::complement(geometry::dilate(untouchable_, geometry::reflected(model_.whole_guard), work_), work_);
  for (int z = work_.hi.z - 2; z >= work_.lo.z; --z)
    for (int y = work_.lo.y; y < work_.hi.y; ++y) {
      auto row = allowed.row(y, z);
      const auto above = allowed.row(y, z + 1);
      for (std::size_t w = 0; w < row.size(); ++w) row[w] &= above[w];
    }

  // Column tops of everything there, wide enough for the holder.
  reach_ = reach_offsets(model_, h_);
  const int R = int(std::floor(model_.max_radius / h_)) + 1;
  tops_box_ = {{work_.lo.x - R, work_.lo.y - R, std::min(work_.lo.z, all.lo.z)}, {work_.hi.x + R, work_.hi.y + R, all.hi.z}};
  untouchable_tops_ = column_top_indices(untouchable_, tops_box_);
  tops_ = untouchable_tops_;
  refresh_tops(tops_box_);

  // Levels: top-down every `down` voxels from the top, plus every floor of the ROI.
  std::set<int, std::greater<int>> levels;
  for (int k = rb.hi.z - down; k > rb.lo.z; k -= down) levels.insert(k);
  levels.insert(rb.lo.z);
  for (int z = rb.lo.z + 1; z < rb.hi.z; ++z) {
    bool floor_here = false;
    for (int y = rb.lo.y; y < rb.hi.y && !floor_here; ++y) {
      const auto now = remaining_.row(y, z), below = remaining_.row(y, z - 1);
      for (std::size_t w = 0; w < now.size(); ++w)
        if (now[w] & ~below[w]) {
          floor_here = true;
          break;
        }
    }
    if (floor_here) levels.insert(z);
  }

  const bool alternate = options_.raster == PocketRaster::Alternate;
  int level_number = 0;
  for (const int k : levels) {
    if (remaining_.empty()) break;
    SliceMask usable = slice_of(allowed, k, work_);
    // Tips whose shank or holder would meet material still there (material the round
    // tool left above, out of its reach): each body disc grown around the columns whose
    // material reaches the disc's lowest level (for the holder, which never ends, exact;
    // for the shank, conservative).
    const IndexBox now = remaining_.bounding_box();
    if (now.hi.z - 1 >= k + model_.body_first_level) {
      const std::vector<int> top = column_top_indices(remaining_, work_);
      const int nx = work_.hi.x - work_.lo.x;
      for (const auto& [radius, from] : model_.body_discs) {
        SliceMask reached(work_.lo.x, work_.lo.y, nx, work_.hi.y - work_.lo.y);
        for (int y = work_.lo.y; y < work_.hi.y; ++y)
          for (int x = work_.lo.x; x < work_.hi.x; ++x)
            if (top[std::size_t(y - work_.lo.y) * std::size_t(nx) + std::size_t(x - work_.lo.x)] >= k + from)
              reached.set(x, y);
        if (!reached.empty()) usable = usable.without(grow_by_disc(reached, radius));
      }
    }
    // Tips whose cutter meets material still there: each disc of the cutter grown
    // around the material in the layers it reaches.
    SliceMask useful(work_.lo.x, work_.lo.y, work_.hi.x - work_.lo.x, work_.hi.y - work_.lo.y);
    for (const auto& [radius, levels] : model_.cutter_discs) {
      SliceMask material = slice_of(remaining_, k + levels.front(), work_);
      for (std::size_t i = 1; i < levels.size(); ++i) material |= slice_of(remaining_, k + levels[i], work_);
      if (!material.empty()) useful |= grow_by_disc(material, radius);
    }
    useful &= usable;
    if (useful.empty()) continue;
    ++level_number;

    air_cache_.clear();
    pending_comment_ = "level " + std::to_string(level_number) + " z=" + mm(centre_z(k));
    if (options_.strategy == PocketStrategy::Zigzag) {
      const bool along_x = options_.raster == PocketRaster::AlongX || (alternate && level_number % 2 == 1);
      cut_paths(zigzag_rows(useful, along_x, over), k, usable);
      if (options_.wall_pass == WallPass::Contour) cut_paths(chain_paths(boundary_cells(useful), useful, usable), k, usable);
    } else {
      // Rings close enough that every cell between two is within the cutter's reach,
      // cut from the innermost out.
      const double ring = std::clamp(std::min(step_over, model_.cutter_radius - 1.5 * h_), h_, std::max(step_over, h_));
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
  if (started_ && at_.z < safe_z_) move(MoveKind::Rapid, {at_.x, at_.y, safe_z_}, 0, false);

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
  if (skipped_entries_ > 0)
    path_.warnings.push_back(std::to_string(skipped_entries_) +
                             " passes skipped: the shank or holder would meet material on the way down to them");
  if (!started_) path_.warnings.push_back("no tool position reaches the region without touching what must remain");
  return path_;
}

}  // namespace

Toolpath pocket_path(const Solid& roi_part, const Solid& keep_part, const Solid& stock_part,
                     const config::CuttingTool& tool_in, const config::Setup& setup, const PocketOptions& options) {
  for (const Solid* s : {&keep_part, &stock_part})
    if (!s->empty() && !(s->lattice() == roi_part.lattice()))
      throw std::invalid_argument("pocket_path: the ROI, keep and stock solids are on different lattices");
  const config::CuttingTool tool = with_defaults(tool_in);
  Toolpath path;
  path.process = Process::Milling;
  path.instrument = tool.name.empty() ? "T" + std::to_string(tool.number) : tool.name;
  path.tool_number = tool.number;
  path.setup = setup.name;
  const Solid roi = part_to_work(roi_part, setup.approach);
  const Solid keep = keep_part.empty() ? Solid(roi.lattice(), {}) : part_to_work(keep_part, setup.approach);
  const Solid stock = stock_part.empty() ? Solid(roi.lattice(), {}) : part_to_work(stock_part, setup.approach);
  PocketBuilder builder(tool, options, path);
  builder.run(roi, keep, stock);
  return path;
}

}  // namespace hybridctl::toolpaths
