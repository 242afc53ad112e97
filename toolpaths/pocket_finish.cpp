#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "geometry/voxelize.hpp"
#include "toolpaths/pocket_builder.hpp"

// Wall finishing (docs/toolpaths.md, "Wall finishing"): after a level is roughed on the
// lattice, a flat cutter follows the boundary of the tip positions where it would cut into
// the design (toolpaths/wall_finish.hpp), so that its side stands on the design's real
// walls, where that finishes what this level removes and keeps clear of everything else.

namespace hybridctl::toolpaths::pocket {
namespace {

constexpr double kSqrtHalf = 0.70710678118654757;
constexpr double kPi = 3.14159265358979323846;
// How far a lead arc's chords may lie inside it (mm): half arc fitting's chord tolerance.
constexpr double kLeadSagitta = 0.0005;

double distance(Point2 a, Point2 b) { return std::hypot(b.x - a.x, b.y - a.y); }

Point2 lerp(Point2 a, Point2 b, double t) { return {a.x + t * (b.x - a.x), a.y + t * (b.y - a.y)}; }

Point2 unit(Point2 a, Point2 b) {
  const double d = distance(a, b);
  return d > 0 ? Point2{(b.x - a.x) / d, (b.y - a.y) / d} : Point2{1, 0};
}

double distance_to_segment(Point2 p, Point2 a, Point2 b) {
  const double dx = b.x - a.x, dy = b.y - a.y, len2 = dx * dx + dy * dy;
  const double t = len2 > 0 ? std::clamp(((p.x - a.x) * dx + (p.y - a.y) * dy) / len2, 0.0, 1.0) : 0.0;
  return std::hypot(p.x - a.x - t * dx, p.y - a.y - t * dy);
}

double length_of(const std::vector<Point2>& pts) {
  double l = 0;
  for (std::size_t i = 1; i < pts.size(); ++i) l += distance(pts[i - 1], pts[i]);
  return l;
}

// The polyline from arc length `s` on (s clamped to it).
std::vector<Point2> from_length(const std::vector<Point2>& pts, double s) {
  std::vector<Point2> out;
  double at = 0;
  for (std::size_t i = 1; i < pts.size(); ++i) {
    const double d = distance(pts[i - 1], pts[i]);
    if (out.empty() && at + d > s) out.push_back(lerp(pts[i - 1], pts[i], d > 0 ? (s - at) / d : 0));
    if (!out.empty() && !(out.back() == pts[i])) out.push_back(pts[i]);
    at += d;
  }
  if (out.empty() && !pts.empty()) out.push_back(pts.back());
  return out;
}

std::vector<Point2> reversed(std::vector<Point2> pts) {
  std::reverse(pts.begin(), pts.end());
  return pts;
}

// A closed loop as a polyline that starts and ends at arc length `s` along it.
std::vector<Point2> loop_from(const std::vector<Point2>& loop, double s) {
  std::vector<Point2> twice = loop;
  twice.insert(twice.end(), loop.begin(), loop.end());
  twice.push_back(loop.front());
  std::vector<Point2> out = from_length(twice, s);
  const double perimeter = length_of(std::vector<Point2>(twice.begin(), twice.begin() + std::ptrdiff_t(loop.size()) + 1));
  // Keep one lap: cut the tail where it is back at the start.
  std::vector<Point2> lap{out.front()};
  double at = 0;
  for (std::size_t i = 1; i < out.size(); ++i) {
    const double d = distance(out[i - 1], out[i]);
    if (at + d >= perimeter - 1e-9) {
      lap.push_back(out.front());
      break;
    }
    lap.push_back(out[i]);
    at += d;
  }
  return lap;
}

// Stretches of a move, mm along it.
using Interval = std::pair<double, double>;

}  // namespace

// A piece of a level's contour to finish: tip positions in cutting order.
struct FinishRun {
  std::vector<Point2> points;
  bool closed = false;  // a whole loop: it may start anywhere
};

void PocketBuilder::start_finishing(const Solid& region, const Solid* design) {
  finishing_ = false;
  if (!options_.finish_walls || !options_.design || options_.design->empty() || tool_.type != config::ToolType::Flat)
    return;
  design_ = design ? *design
                   : geometry::voxelize(geometry::TriangleMesh{*options_.design}, lattice_, "design",
                                        geometry::VoxelizeMethod::ExactScan);
  finish_bands_ = flat_tool_bands(tool_);
  if (finish_bands_.empty()) return;
  roi_ = region;
  stays_ = stays_besides_design();
  // The heights of the design's faces square to the tool axis, either way up: where a wall
  // ends, finished from there when no level is (the flange's rim above the stock kept
  // under it: the level below would reach into that stock).
  face_heights_.clear();
  for (const geometry::Triangle& t : *options_.design)
    if (t[0].z == t[1].z && t[1].z == t[2].z) face_heights_.push_back(t[0].z);
  std::sort(face_heights_.begin(), face_heights_.end(), std::greater<>());
  face_heights_.erase(std::unique(face_heights_.begin(), face_heights_.end()), face_heights_.end());
  // A unit step between two tips whose distance from a set is at least r + m stays at
  // least r from it when (r + m)^2 - (h/2)^2 >= r^2 (the squared distance to a set, less
  // |p|^2, is concave along the step): the roughing's tips keep that much beyond the
  // keep-out region, so no roughing move cuts into the design between voxel centres.
  const double r = model_.cutter_radius;
  rough_margin_ = std::sqrt(r * r + h_ * h_ / 4) - r + 1e-4;
  finishing_ = true;
}

TipKeepOut PocketBuilder::keep_out_at(double z) const { return tip_keep_out(*options_.design, z, finish_bands_); }

SliceMask PocketBuilder::cells_in(const TipKeepOut& region) const {
  return cells_inside(region, SliceMask(work_.lo.x, work_.lo.y, work_.hi.x - work_.lo.x, work_.hi.y - work_.lo.y),
                      lattice_);
}

double PocketBuilder::contact_height_at(Point2 p, Part part, const std::vector<int>& tops) const {
  const std::vector<double>& run = part == Part::Whole    ? model_.run_whole
                                   : part == Part::Cutter ? model_.run_cutter
                                                          : model_.run_body;
  const double R = model_.max_radius;
  const Cell lo = cell_of({p.x - R, p.y - R}), hi = cell_of({p.x + R, p.y + R});
  // Beyond the column tops known, the tool may meet anything.
  if (lo.x < tops_box_.lo.x || lo.y < tops_box_.lo.y || hi.x >= tops_box_.hi.x || hi.y >= tops_box_.hi.y) return kInf;
  double need = -kInf;
  for (int y = lo.y; y <= hi.y; ++y)
    for (int x = lo.x; x <= hi.x; ++x) {
      const int top = tops[std::size_t(y - tops_box_.lo.y) * std::size_t(tops_box_.hi.x - tops_box_.lo.x) +
                           std::size_t(x - tops_box_.lo.x)];
      if (top == kNoVoxel) continue;
      const double dx = lattice_.origin.x + (x + 0.5) * h_ - p.x, dy = lattice_.origin.y + (y + 0.5) * h_ - p.y;
      const double zmin = first_reach(run, model_.profile_step, dx * dx + dy * dy);
      if (std::isinf(zmin)) continue;
      need = std::max(need, centre_z(top) - zmin);
    }
  return need;
}

double PocketBuilder::rapid_stop_at(Point2 p, double at_least) const {
  return std::max(rapid_stop(cell_of(p), at_least),
                  contact_height_at(p, Part::Whole) + options_.material_allowance + options_.retract_clearance);
}

void PocketBuilder::stamp_polyline(const std::vector<Point2>& pts, double z) {
  if (pts.empty()) return;
  const double r = model_.cutter_radius;
  double x0 = pts[0].x, x1 = x0, y0 = pts[0].y, y1 = y0;
  for (const Point2& p : pts) x0 = std::min(x0, p.x), x1 = std::max(x1, p.x), y0 = std::min(y0, p.y), y1 = std::max(y1, p.y);
  const Cell lo = cell_of({x0 - r, y0 - r}), hi = cell_of({x1 + r, y1 + r});
  SliceMask swept(lo.x, lo.y, hi.x - lo.x + 1, hi.y - lo.y + 1);
  // The cells whose centres the cutter's disc sweeps; a centre at exactly the radius is
  // left as material (the model may only over-estimate what is there).
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const Point2 a = pts[i], b = pts[i + 1 < pts.size() ? i + 1 : i];
    const Cell slo = cell_of({std::min(a.x, b.x) - r, std::min(a.y, b.y) - r});
    const Cell shi = cell_of({std::max(a.x, b.x) + r, std::max(a.y, b.y) + r});
    for (int y = slo.y; y <= shi.y; ++y)
      for (int x = slo.x; x <= shi.x; ++x) {
        const Point2 c{lattice_.origin.x + (x + 0.5) * h_, lattice_.origin.y + (y + 0.5) * h_};
        if (distance_to_segment(c, a, b) < r - 1e-6) swept.set(x, y);
      }
  }
  // The layers whose centres the cutter holds: [z, z + flute], the top left as material.
  const IndexBox storage = remaining_.storage_box();
  const int k0 = std::max(storage.lo.z, int(std::ceil((z - lattice_.origin.z) / h_ - 0.5 - 1e-9)));
  const int k1 = std::min(storage.hi.z - 1,
                          int(std::floor((z + tool_.flute_length - 1e-6 - lattice_.origin.z) / h_ - 0.5)));
  const int first_word = remaining_.first_word(), words = remaining_.words_per_row();
  std::vector<std::uint64_t> row_mask(std::size_t(words > 0 ? words : 0));
  for (int y = std::max(lo.y, storage.lo.y); y <= std::min(hi.y, storage.hi.y - 1); ++y) {
    std::fill(row_mask.begin(), row_mask.end(), 0);
    bool any = false;
    for (int x = std::max(lo.x, storage.lo.x); x <= std::min(hi.x, storage.hi.x - 1); ++x)
      if (swept.at(x, y)) {
        row_mask[std::size_t((x >> 6) - first_word)] |= std::uint64_t{1} << (x & 63);
        any = true;
      }
    if (!any) continue;
    for (int kk = k0; kk <= k1; ++kk) {
      const std::span<std::uint64_t> row = remaining_.row(y, kk);
      for (std::size_t w = 0; w < row.size(); ++w) row[w] &= ~row_mask[w];
    }
  }
  refresh_tops({{lo.x, lo.y, 0}, {hi.x + 1, hi.y + 1, 1}});
  air_cache_.clear();
}

// What the finishing passes of one tip height must keep to and clear of.
struct FinishLevel {
  const TipKeepOut* keep_out = nullptr;
  double z = 0, r = 0;
  double step = 0;  // samples along the contour, mm
  geometry::Vec3 origin;
  double h = 1;
  int reach = 0;  // cells round a move where a centre the cutter holds can be
  // Where a pass is this level's; centres of what stays that is not design, in the
  // cutter's layers; the cells where the body would meet material (conservative).
  SliceMask near, held, body_block;

  Cell cell_of(Point2 p) const { return {int(std::floor((p.x - origin.x) / h)), int(std::floor((p.y - origin.y) / h))}; }
  // The stretches [lo, hi] (mm along a -> b) where the cutter holds a centre of `held`
  // (within r + 0.0002 mm: the G-code's rounding); all of it when the move leaves the
  // window the centres are known in.
  void held_along(Point2 a, Point2 b, std::vector<Interval>& out) const {
    out.clear();
    const double len = distance(a, b);
    const Point2 u = unit(a, b);
    const Cell lo = cell_of({std::min(a.x, b.x), std::min(a.y, b.y)}), hi = cell_of({std::max(a.x, b.x), std::max(a.y, b.y)});
    if (!held.inside_window(lo.x - reach, lo.y - reach) || !held.inside_window(hi.x + reach, hi.y + reach)) {
      out.push_back({-1, len + 1});
      return;
    }
    const double rr = r + 2e-4;
    for (int y = lo.y - reach; y <= hi.y + reach; ++y)
      for (int x = lo.x - reach; x <= hi.x + reach; ++x) {
        if (!held.at(x, y)) continue;
        const double wx = origin.x + (x + 0.5) * h - a.x, wy = origin.y + (y + 0.5) * h - a.y;
        const double t = len > 0 ? wx * u.x + wy * u.y : 0.0;
        const double e = len > 0 ? std::abs(wx * u.y - wy * u.x) : std::hypot(wx, wy);
        if (e > rr) continue;
        const double half = len > 0 ? std::sqrt(rr * rr - e * e) : 0.0;
        if (t + half < 0 || t - half > len) continue;
        out.push_back({t - half, t + half});
      }
  }
  bool body_clear(Point2 p) const {
    const Cell q = cell_of(p);
    return body_block.inside_window(q.x, q.y) && !body_block.at(q);
  }
  // A straight move at the level: out of the keep-out region, the cutter holding nothing
  // that stays, the body clear at every sample.
  bool segment_safe(Point2 a, Point2 b) const {
    if (!keep_out->segment_clear(a, b)) return false;
    std::vector<Interval> stretches;
    held_along(a, b, stretches);
    if (!stretches.empty()) return false;
    const int m = std::max(1, int(std::ceil(distance(a, b) / step)));
    for (int j = 0; j <= m; ++j)
      if (!body_clear(lerp(a, b, double(j) / m))) return false;
    return true;
  }
};

namespace {

// The loops of the keep-out region cut into runs: the pieces where every sample is this
// level's and safe. Samples every `step` along each edge, and round each stretch where
// the cutter would hold what stays: just before it, in it, just after it (so a run never
// spans one).
std::vector<FinishRun> finish_runs(const FinishLevel& f) {
  struct Sample {
    Point2 p;
    bool vertex = false, ok = false;
  };
  std::vector<FinishRun> runs;
  std::vector<Interval> held;
  std::vector<double> ts;
  for (const std::vector<Point2>& loop : f.keep_out->loops()) {
    const std::size_t n = loop.size();
    if (n < 3) continue;
    std::vector<Sample> samples;
    for (std::size_t i = 0; i < n; ++i) {
      const Point2 a = loop[i], b = loop[(i + 1) % n];
      const double len = distance(a, b);
      f.held_along(a, b, held);
      const int m = std::max(1, int(std::ceil(len / f.step)));
      ts.clear();
      for (int j = 0; j < m; ++j) ts.push_back(len * j / m);
      for (const Interval& iv : held)
        for (const double t : {iv.first - 1e-6, (iv.first + iv.second) / 2, iv.second + 1e-6})
          if (t > 0 && t < len) ts.push_back(t);
      std::sort(ts.begin(), ts.end());
      for (const double t : ts) {
        const Point2 p = lerp(a, b, len > 0 ? t / len : 0);
        bool ok = f.near.at(f.cell_of(p)) && f.body_clear(p);
        for (const Interval& iv : held) ok = ok && !(t >= iv.first && t <= iv.second);
        samples.push_back({p, t == 0, ok});
      }
    }
    const auto bad = std::find_if(samples.begin(), samples.end(), [](const Sample& s) { return !s.ok; });
    if (bad == samples.end()) {
      runs.push_back({loop, true});
      continue;
    }
    // From the first sample that is not ok round the loop: each stretch of ok samples,
    // from its first sample, turning at the loop's vertices, to its last.
    const std::size_t start = std::size_t(bad - samples.begin()), ns = samples.size();
    FinishRun cur;
    for (std::size_t i = 1; i <= ns; ++i) {
      const Sample& s = samples[(start + i) % ns];
      if (s.ok) {
        if (cur.points.empty() || s.vertex || !samples[(start + i + 1) % ns].ok) cur.points.push_back(s.p);
      } else if (!cur.points.empty()) {
        if (cur.points.size() >= 2) runs.push_back(std::move(cur));
        cur = {};
      }
    }
    if (cur.points.size() >= 2) runs.push_back(std::move(cur));
  }
  return runs;
}

}  // namespace

std::optional<FinishLevel> PocketBuilder::finish_level(const TipKeepOut& keep_out, int k, int k_above, double z) const {
  FinishLevel f;
  f.keep_out = &keep_out;
  f.z = z;
  f.r = model_.cutter_radius;
  f.step = h_ / 4;
  f.origin = lattice_.origin;
  f.h = h_;
  f.reach = int(std::ceil(f.r / h_)) + 1;
  const int nx = work_.hi.x - work_.lo.x, ny = work_.hi.y - work_.lo.y;
  auto layer_of = [&](double height) { return (height - lattice_.origin.z) / h_ - 0.5; };
  // The layers whose centres the cutter holds.
  const int c0 = int(std::ceil(layer_of(z) - 1e-9)), c1 = int(std::floor(layer_of(z + tool_.flute_length) + 1e-9));
  // Where a pass is this level's: near what the level may remove (the region's layers [k, k_above))
  // and near design material kept at the cutter's layers. Other walls are other levels' or
  // other actions'. The design's voxels have their centres inside the STL, which the
  // keep-out region keeps the cutter off: what it must not hold is what stays besides.
  SliceMask roi_here(work_.lo.x, work_.lo.y, nx, ny), kept_design = roi_here;
  f.held = roi_here;
  for (int kk = k; kk < k_above; ++kk) roi_here |= slice_of(roi_, kk, work_);
  for (int kk = c0; kk <= c1; ++kk) {
    const SliceMask u = slice_of(untouchable_, kk, work_), d = slice_of(design_, kk, work_);
    f.held |= slice_of(stays_, kk, work_);
    SliceMask kept = u;
    kept &= d;
    kept_design |= kept;
  }
  if (roi_here.empty() || kept_design.empty()) return std::nullopt;  // nothing this level removes, or no wall
  f.near = grow_by_disc(roi_here, f.r / h_ + 2);
  f.near &= grow_by_disc(kept_design, f.r / h_ + 2);
  if (f.near.empty()) return std::nullopt;
  // The body (shank, holder) meets none of the material there but the design, whose walls
  // the keep-out region keeps it off exactly: the material that stays (not design) and the
  // ROI still there, in the layers each body section reaches, grown by its radius and the
  // distance from a point to its cell's centre and half a sample (conservative).
  f.body_block = SliceMask(work_.lo.x, work_.lo.y, nx, ny);
  const IndexBox ustore = untouchable_.storage_box(), rstore = remaining_.storage_box();
  const int top_layer = std::max(ustore.hi.z, rstore.hi.z) - 1;
  for (const geometry::AxialSection& s : model_.body) {
    const int b0 = int(std::ceil(layer_of(z + s.from) - 1e-9));
    const int b1 = std::isinf(s.to) ? top_layer : int(std::floor(layer_of(z + s.to) + 1e-9));
    SliceMask reached(work_.lo.x, work_.lo.y, nx, ny);
    for (int kk = std::max(b0, std::min(ustore.lo.z, rstore.lo.z)); kk <= std::min(b1, top_layer); ++kk) {
      reached |= slice_of(untouchable_, kk, work_).without(slice_of(design_, kk, work_));
      reached |= slice_of(remaining_, kk, work_);
    }
    const double r2 = s.kind == geometry::AxialSection::Kind::Cylinder
                          ? s.radius * s.radius
                          : std::max(s.radius_squared_at(s.from), s.radius_squared_at(s.to));
    if (!reached.empty())
      f.body_block |= grow_by_disc(reached, std::sqrt(std::max(0.0, r2)) / h_ + kSqrtHalf + f.step / (2 * h_) + 1e-9);
  }
  return f;
}

// The lead at `p` on the contour, heading `t`, on the air side (the left: the keep-out
// region is on the right). First choice, a quarter circle tangent to the contour at p
// whose centre is in air (so the whole circle keeps to the air side of the contour's
// tangent there): the cutter comes onto the wall (lead-in) or leaves it (lead-out) along
// the wall's own direction, without a mark where it meets it. Its radius is the cutter's,
// else smaller, down to a voxel; its chords are at most 0.0005 mm inside the circle, so
// that arc fitting makes it one G2/G3 (docs/toolpaths.md, "Arc fitting"). Every chord
// must be a safe move at the level and, for a lead-in, the tool must come straight down
// in air at its start. Else the straight lead: a point obliquely behind (lead-in) or ahead
// (lead-out) or square to it, 1 to r/h + 3 voxels out.
std::optional<std::vector<Point2>> PocketBuilder::finish_lead(const FinishLevel& f, Point2 p, Point2 t, bool in) const {
  const Point2 nrm{-t.y, t.x};
  auto down_in_air = [&](Point2 a) { return !in || contact_height_at(a, Part::Whole) < f.z - kHeightSlack; };
  for (const double radius : {f.r, 0.75 * f.r, 0.5 * f.r, 0.25 * f.r, h_}) {
    if (radius < h_ - 1e-12) continue;
    const Point2 c{p.x + radius * nrm.x, p.y + radius * nrm.y};
    const double chord_angle = 2 * std::acos(std::max(-1.0, 1 - kLeadSagitta / radius));
    const int chords = std::max(4, int(std::ceil((kPi / 2) / chord_angle)));
    // The point at angle phi (0: p) along the circle, back (lead-in) or ahead (lead-out):
    // p - c = -radius * nrm, turned by -phi or +phi.
    auto at = [&](double phi) {
      const double turn = in ? -phi : phi, cs = std::cos(turn), sn = std::sin(turn);
      const Point2 v{-nrm.x, -nrm.y};
      return Point2{c.x + radius * (v.x * cs - v.y * sn), c.y + radius * (v.x * sn + v.y * cs)};
    };
    std::vector<Point2> lead;
    bool safe = true;
    Point2 prev = p;
    for (int j = 1; j <= chords && safe; ++j) {
      const Point2 q = at((kPi / 2) * j / chords);
      safe = !f.keep_out->contains(q) && f.segment_safe(prev, q);
      lead.push_back(q);
      prev = q;
    }
    if (!safe || !down_in_air(lead.back())) continue;
    if (in) std::reverse(lead.begin(), lead.end());
    return lead;
  }
  const double s = in ? -1 : 1;
  const Point2 oblique{(nrm.x + s * t.x) * kSqrtHalf, (nrm.y + s * t.y) * kSqrtHalf};
  const int steps = int(std::ceil(f.r / h_)) + 3;
  for (int i = 1; i <= steps; ++i)
    for (const Point2 dir : {oblique, nrm}) {
      const Point2 a{p.x + i * h_ * dir.x, p.y + i * h_ * dir.y};
      if (f.keep_out->contains(a) || !f.segment_safe(a, p) || !down_in_air(a)) continue;
      return std::vector<Point2>{a};
    }
  return std::nullopt;
}

// A run as it is cut: its lead-in, the run (an open one from its first point that leads
// in to its last that leads out; a closed one from the first of 24 points round it,
// nearest `from` first, where both work, round to it again), its lead-out.
std::optional<FinishPass> PocketBuilder::finish_pass(const FinishLevel& f, const FinishRun& run, Point2 from) const {
  auto with_leads = [&](const std::vector<Point2>& body) -> std::optional<FinishPass> {
    const std::size_t m = body.size();
    std::optional<std::vector<Point2>> a = finish_lead(f, body[0], unit(body[0], body[1]), true);
    if (!a) return std::nullopt;
    std::optional<std::vector<Point2>> b = finish_lead(f, body[m - 1], unit(body[m - 2], body[m - 1]), false);
    if (!b) return std::nullopt;
    return FinishPass{std::move(*a), body, std::move(*b)};
  };
  if (run.closed) {
    std::vector<Point2> closed = run.points;
    closed.push_back(run.points.front());
    const double perimeter = length_of(closed);
    constexpr int kStarts = 24;
    std::vector<std::pair<double, double>> starts;  // (distance from `from`, arc length)
    for (int i = 0; i < kStarts; ++i) {
      const double s = perimeter * i / kStarts;
      starts.push_back({distance(from_length(closed, s).front(), from), s});
    }
    std::sort(starts.begin(), starts.end());
    for (const auto& start : starts) {
      const std::vector<Point2> lap = loop_from(run.points, start.second);
      if (lap.size() < 3) continue;
      if (auto pass = with_leads(lap)) return pass;
    }
    return std::nullopt;
  }
  const double len = length_of(run.points);
  for (double s = 0; s < len - 1e-9; s += h_) {
    const std::vector<Point2> tail = from_length(run.points, s);
    if (tail.size() < 2) break;
    if (!finish_lead(f, tail[0], unit(tail[0], tail[1]), true)) continue;
    const std::vector<Point2> back = reversed(tail);
    const double tlen = length_of(back);
    for (double e = 0; e < tlen - 1e-9; e += h_) {
      const std::vector<Point2> body = reversed(from_length(back, e));
      if (body.size() < 2) break;
      if (auto pass = with_leads(body)) return pass;
    }
    break;
  }
  return std::nullopt;
}

// Gets to the pass's lead-in (a feed at the level from where the tool is when that is
// safe, else down from above in air), cuts it and takes what the cutter swept from the
// material still there. The lead-in's last move and the lead-out's first carry the
// comments: an arc is fitted to what follows a comment, never across one.
void PocketBuilder::cut_finish_pass(const FinishLevel& f, const FinishPass& pass) {
  spindle_ = tool_.finishing_spindle_speed();
  const Point2 here{at_.x, at_.y}, a = pass.lead_in.front();
  std::vector<Point2> swept;
  if (at_level_ && std::abs(at_.z - f.z) <= kHeightSlack && f.segment_safe(here, a)) {
    move(MoveKind::Feed, {a.x, a.y, f.z}, tool_.feed, true, "link");
    swept.push_back(here);
  } else {
    retract();
    go_above(a, rapid_stop_at(a, f.z));
    move(MoveKind::Feed, {a.x, a.y, f.z}, tool_.plunge_feed, false, "plunge in air");
    at_level_ = true;
  }
  auto feed = [&](Point2 q, const char* comment) {
    move(MoveKind::Feed, {q.x, q.y, f.z}, tool_.finishing_feed(), true, comment);
  };
  for (std::size_t i = 1; i < pass.lead_in.size(); ++i) feed(pass.lead_in[i], i == 1 ? "finish lead-in arc" : "");
  feed(pass.body.front(), "finish lead-in");
  for (std::size_t i = 1; i < pass.body.size(); ++i) feed(pass.body[i], "");
  for (std::size_t i = 0; i < pass.lead_out.size(); ++i) feed(pass.lead_out[i], i == 0 ? "finish lead-out" : "");
  swept.insert(swept.end(), pass.lead_in.begin(), pass.lead_in.end());
  swept.insert(swept.end(), pass.body.begin(), pass.body.end());
  swept.insert(swept.end(), pass.lead_out.begin(), pass.lead_out.end());
  stamp_polyline(swept, f.z);
  spindle_ = 0;
}

void PocketBuilder::finish_walls(const TipKeepOut& keep_out, int k, int k_above, double z) {
  if (keep_out.empty()) return;
  const std::optional<FinishLevel> f = finish_level(keep_out, k, k_above, z);
  if (!f) return;
  std::vector<FinishRun> runs = finish_runs(*f);
  level_ = k;
  bool first = true;
  while (!runs.empty()) {
    // The nearest run to where the tool is.
    const Point2 here{at_.x, at_.y};
    std::size_t pick = 0;
    double best = kInf;
    for (std::size_t i = 0; i < runs.size(); ++i) {
      double d = distance(here, runs[i].points.front());
      if (runs[i].closed)
        for (const Point2& p : runs[i].points) d = std::min(d, distance(here, p));
      if (d < best) best = d, pick = i;
    }
    const FinishRun run = std::move(runs[pick]);
    runs.erase(runs.begin() + std::ptrdiff_t(pick));
    const double run_length = run.closed ? length_of(loop_from(run.points, 0)) : length_of(run.points);
    const std::optional<FinishPass> pass = finish_pass(*f, run, here);
    if (!pass) {
      ++finish_skipped_;
      finish_skipped_length_ += run_length;
      continue;
    }
    const double cut_length = length_of(pass->body);
    finish_skipped_length_ += std::max(0.0, run_length - cut_length);
    finish_length_ += cut_length;
    ++finish_passes_;
    if (first) pending_comment_ = "wall finish z=" + mm(z);
    first = false;
    cut_finish_pass(*f, *pass);
  }
  retract();
}

// A deposit's beads stand past the voxels they fill, below them too: its layers keep
// their own heights, not the lattice's (the worn hub's overfill, laid from z = 32.3 mm
// under voxels from 32.5). So the walls next to the region are finished on down to
// material_allowance under the lowest level, a layer at a time (and from the faces square
// to the axis between), wherever finish_level finds a wall there the region borders.
void PocketBuilder::finish_walls_below(int k_low, double z_low) {
  const double bottom = lattice_.origin.z + k_low * h_ - options_.material_allowance;
  int k_above = k_low;
  double z_above = z_low;
  for (int k = k_low - 1; centre_z(k) >= bottom - 1e-9; --k) {
    const double z = centre_z(k);
    finish_walls(keep_out_at(z), k, k_above, z);
    for (const double zf : face_heights_)
      if (zf > z + 1e-6 && zf < z_above - 1e-6) finish_walls(keep_out_at(zf), k, k_above, zf);
    k_above = k;
    z_above = z;
  }
}

}  // namespace hybridctl::toolpaths::pocket
