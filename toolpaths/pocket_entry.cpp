#include <algorithm>
#include <numbers>

#include "toolpaths/pocket_builder.hpp"

// How the pocket generator gets the tool down to the start of a pass at a level
// (docs/toolpaths.md, "Entry"): a plunge where the way down is in air, else a lead-in
// from air along the first leg, else a ramp along it (or along the longest free row).

namespace hybridctl::toolpaths::pocket {

bool PocketBuilder::in_air(Cell c, int k) {
  const auto key = std::pair<int, int>{c.x, c.y};
  if (const auto it = air_cache_.find(key); it != air_cache_.end()) return it->second;
  const bool air = contact_height(c, Part::Whole) < level_z(k) - kHeightSlack;
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

void PocketBuilder::go_above(Cell c, double stop) {
  const Vec3 centre = at_cell(c, 0);
  go_above(Point2{centre.x, centre.y}, stop);
}

void PocketBuilder::go_above(Point2 p, double stop) {
  const Vec3 top{p.x, p.y, safe_z_};
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
  move(MoveKind::Rapid, {p.x, p.y, std::min(safe_z_, stop)}, 0, false);
}

// Down at `a`, where the whole tool meets nothing on the way, then over to the pass's
// start `b` (a lead-in when they differ).
void PocketBuilder::plunge_in_air(Cell a, Cell b, double zk) {
  go_above(a, rapid_stop(a, zk));
  move(MoveKind::Feed, at_cell(a, zk), tool_.plunge_feed, false, "plunge in air");
  at_level_ = true;
  for_leg_cells(a, b, [&](Cell c) { run_cells_.push_back(c); });
  if (!(a == b)) move(MoveKind::Feed, at_cell(b, zk), tool_.feed, true, "lead-in");
}

bool PocketBuilder::enter(const CellPath& p, int k, const SliceMask& usable) {
  const double zk = level_z(k);
  const Cell b = p.points.front();
  // 1. Air all the way down, at the start or on the line before it: plunge there (and
  // lead in).
  if (const std::optional<Cell> a = air_entry(p, k, usable)) {
    plunge_in_air(*a, b, zk);
    return true;
  }
  if (contact_height(b, Part::Body) >= zk - kHeightSlack) {
    // The shank or holder would meet material on the way down: no way in here.
    ++skipped_entries_;
    return false;
  }
  ramp_in(p, zk, usable);
  return true;
}

double PocketBuilder::ramp_start(Cell b, Cell d, int m, double zk) const {
  double z = contact_height(b, Part::Cutter);
  for (int i = 1; i <= m; ++i) z = std::max(z, contact_height({b.x + i * d.x, b.y + i * d.y}, Part::Cutter));
  return std::max(z, zk) + kHeightSlack * 10;
}

namespace {

// The row a ramp runs along: a direction and its length in cells.
struct RampRow {
  Cell dir{0, 0};
  int run = 0;
};

// The first leg's direction (then the four axis directions) from `b`: the first that
// gives `wanted` usable cells, unless another row is much longer.
RampRow ramp_row(const CellPath& p, const SliceMask& usable, int wanted) {
  const Cell b = p.points.front();
  std::vector<Cell> ramp_dirs;
  if (p.points.size() >= 2) ramp_dirs.push_back(unit_towards(p.points[0], p.points[1]));
  for (Cell d : {Cell{1, 0}, Cell{-1, 0}, Cell{0, 1}, Cell{0, -1}})
    if (ramp_dirs.empty() || !(d == ramp_dirs[0])) ramp_dirs.push_back(d);
  RampRow best;
  for (std::size_t i = 0; i < ramp_dirs.size(); ++i) {
    const Cell d = ramp_dirs[i];
    int run = 0;
    while (run < wanted && usable.at(b.x + (run + 1) * d.x, b.y + (run + 1) * d.y)) ++run;
    // The first leg's direction wins unless another row is much longer.
    if (run > best.run * (i == 0 ? 1 : 2) || (best.run == 0 && run > 0)) best = {d, run};
    if (i == 0 && run >= wanted) break;
  }
  return best;
}

}  // namespace

// 3. Ramp down along the first leg (or the longest free row from the start).
void PocketBuilder::ramp_in(const CellPath& p, double zk, const SliceMask& usable) {
  const Cell b = p.points.front();
  const double tan_a = std::tan(std::clamp(options_.ramp_angle_deg, 0.01, 90.0) * std::numbers::pi / 180.0);
  const double z_guess = ramp_start(b, {0, 0}, 0, zk);
  const RampRow row = ramp_row(p, usable, std::max(1, int(std::ceil((z_guess - zk) / tan_a / h_))));
  const double z_rs = ramp_start(b, row.dir, row.run, zk);
  go_above(b, rapid_stop(b, z_rs));
  move(MoveKind::Feed, at_cell(b, z_rs), tool_.plunge_feed, false, "down to the material (air)");
  at_level_ = true;
  run_cells_.push_back(b);
  if (row.run == 0 || z_rs - zk <= kHeightSlack * 20) {
    if (z_rs - zk > kHeightSlack * 20) {
      ++plunges_into_material_;
      path_.warnings.push_back("no room to ramp at x=" + mm(at_.x) + " y=" + mm(at_.y) + " z=" + mm(zk) +
                               " (work frame): plunging into material");
    }
    move(MoveKind::Feed, at_cell(b, zk), tool_.plunge_feed, true, "plunge");
    return;
  }
  const Cell r{b.x + row.run * row.dir.x, b.y + row.run * row.dir.y};
  const double length = row.run * h_;
  int legs = int(std::ceil((z_rs - zk) / tan_a / length - 1e-9));
  legs = std::max(2, legs + (legs % 2));
  const double dz = (z_rs - zk) / legs;
  for (int j = 1; j <= legs; ++j) {
    const Cell target = (j % 2 == 1) ? r : b;
    move(MoveKind::Feed, at_cell(target, j == legs ? zk : z_rs - j * dz), tool_.plunge_feed, true,
         j == 1 ? "ramp " + mm(std::atan((z_rs - zk) / legs / length) * 180 / std::numbers::pi) + " deg" : "");
  }
}

}  // namespace hybridctl::toolpaths::pocket
