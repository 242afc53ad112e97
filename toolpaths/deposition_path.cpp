#include "toolpaths/deposition_path.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string>

#include "common/number_text.hpp"
#include "instruments/bead.hpp"
#include "instruments/support_rule.hpp"
#include "toolpaths/contour_reach.hpp"
#include "toolpaths/near_net_contour.hpp"
#include "toolpaths/setup_frame.hpp"
#include "toolpaths/slices.hpp"
#include "toolpaths/wall_finish.hpp"

namespace hybridctl::toolpaths {
namespace {

using geometry::IndexBox;
using geometry::Solid;
using geometry::Vec3;

constexpr double kNone = -std::numeric_limits<double>::infinity();
// Raster lines are nudged off voxel faces by this fraction of a voxel so that a line never
// runs exactly along a face (where "which side" would be a rounding accident).
constexpr double kLineNudge = 1e-7;
// Warnings per kind before they are summarised.
constexpr int kMaxWarningsPerKind = 20;

using Vec2 = Point2;

std::string mm(double v) { return fixed_number(v, 3); }

// A polyline of deposition at one height.
struct Pass {
  std::vector<Vec2> points;
};

// The per-column state of the build, over an XY window of cells.
struct ColumnMap {
  IndexBox window;
  int nx = 0, ny = 0;
  std::vector<double> values;

  ColumnMap() = default;
  ColumnMap(const IndexBox& w, double fill)
      : window(w), nx(w.hi.x - w.lo.x), ny(w.hi.y - w.lo.y),
        values(std::size_t(std::max(nx, 0)) * std::size_t(std::max(ny, 0)), fill) {}
  bool inside(int x, int y) const { return x >= window.lo.x && x < window.hi.x && y >= window.lo.y && y < window.hi.y; }
  double at(int x, int y) const {
    return inside(x, y) ? values[std::size_t(y - window.lo.y) * std::size_t(nx) + std::size_t(x - window.lo.x)] : kNone;
  }
  double& ref(int x, int y) { return values[std::size_t(y - window.lo.y) * std::size_t(nx) + std::size_t(x - window.lo.x)]; }
};

// The raster segments of one layer: lines along direction `d` at spacing `spacing`,
// centred over the region, clipped to its cells by walking the voxel grid along each line.
struct RasterResult {
  std::vector<Pass> passes;
  int dropped = 0;
};

// Where a line leaves the region into `wall` (material already there in this layer) its
// pass runs to the region's edge instead of stopping `inset` short: the bead's round end
// then fuses with the wall instead of leaving notches between the tracks against it (a
// repair deposit's edge along the worn face).
RasterResult raster_layer(const SliceMask& region, const geometry::Lattice& lattice, double angle_deg, double spacing,
                          double min_length, double inset, bool reverse_start, const SliceMask* wall = nullptr) {
  RasterResult out;
  const double h = lattice.voxel_size, ox = lattice.origin.x, oy = lattice.origin.y;
  const double a = angle_deg * std::numbers::pi / 180.0;
  auto snap = [](double v) { return std::abs(v) < 1e-12 ? 0.0 : v; };
  const Vec2 d{snap(std::cos(a)), snap(std::sin(a))};
  const Vec2 n{-d.y, d.x};
  double u_min = std::numeric_limits<double>::infinity(), u_max = -u_min, t_min = u_min, t_max = -u_min;
  for (int y = region.y0(); y < region.y0() + region.ny(); ++y)
    for (int x = region.x0(); x < region.x0() + region.nx(); ++x) {
      if (!region.at(x, y)) continue;
      for (int cy = 0; cy < 2; ++cy)
        for (int cx = 0; cx < 2; ++cx) {
          const double px = ox + (x + cx) * h, py = oy + (y + cy) * h;
          const double u = px * n.x + py * n.y, t = px * d.x + py * d.y;
          u_min = std::min(u_min, u);
          u_max = std::max(u_max, u);
          t_min = std::min(t_min, t);
          t_max = std::max(t_max, t);
        }
    }
  if (!(u_max > u_min)) return out;
  const int lines = std::max(1, int(std::ceil((u_max - u_min) / spacing - 1e-9)));
  const double u_mid = 0.5 * (u_min + u_max);
  for (int j = 0; j < lines; ++j) {
    const double u = u_mid + (j - 0.5 * (lines - 1)) * spacing + kLineNudge * h;
    // Walk the cells the line crosses (Amanatides and Woo), collecting inside intervals.
    const double t0 = t_min - h, t1 = t_max + h;
    const Vec2 s{n.x * u + d.x * t0, n.y * u + d.y * t0};
    int ix = int(std::floor((s.x - ox) / h)), iy = int(std::floor((s.y - oy) / h));
    const int step_x = d.x > 0 ? 1 : -1, step_y = d.y > 0 ? 1 : -1;
    const double inf = std::numeric_limits<double>::infinity();
    double next_x = d.x != 0 ? t0 + ((ox + (ix + (step_x > 0 ? 1 : 0)) * h) - s.x) / d.x : inf;
    double next_y = d.y != 0 ? t0 + ((oy + (iy + (step_y > 0 ? 1 : 0)) * h) - s.y) / d.y : inf;
    const double delta_x = d.x != 0 ? h / std::abs(d.x) : inf, delta_y = d.y != 0 ? h / std::abs(d.y) : inf;
    struct Interval {
      double ta, tb;
      bool wall_a, wall_b;  // the line enters from / leaves into material already there
    };
    std::vector<Interval> intervals;
    double t = t0, open_at = 0;
    bool open = false, open_wall = false;
    int px = ix, py = iy;
    while (t < t1) {
      const bool in = region.at(ix, iy);
      if (in && !open) {
        open = true;
        open_at = t;
        open_wall = wall && wall->at(px, py);
      } else if (!in && open) {
        open = false;
        intervals.push_back({open_at, t, open_wall, wall && wall->at(ix, iy)});
      }
      px = ix, py = iy;
      if (next_x < next_y) {
        t = next_x;
        next_x += delta_x;
        ix += step_x;
      } else {
        t = next_y;
        next_y += delta_y;
        iy += step_y;
      }
    }
    if (open) intervals.push_back({open_at, t1, open_wall, false});
    std::vector<Pass> line;
    for (const Interval& i : intervals) {
      const double length = i.tb - i.ta;
      if (length < min_length - 1e-9) {
        ++out.dropped;
        continue;
      }
      const double e = std::min(inset, std::max(0.0, 0.5 * (length - h)));
      const double ea = i.wall_a ? 0.0 : e, eb = i.wall_b ? 0.0 : e;
      const Vec2 p{n.x * u + d.x * (i.ta + ea), n.y * u + d.y * (i.ta + ea)};
      const Vec2 q{n.x * u + d.x * (i.tb - eb), n.y * u + d.y * (i.tb - eb)};
      line.push_back({{p, q}});
    }
    // Serpentine: every other line runs backwards.
    if ((j % 2 == 1) != reverse_start) {
      std::reverse(line.begin(), line.end());
      for (Pass& p : line) std::reverse(p.points.begin(), p.points.end());
    }
    for (Pass& p : line) out.passes.push_back(std::move(p));
  }
  return out;
}

// The machine file's documented defaults for a head built by hand with them unset.
config::AdditiveHead with_defaults(const config::AdditiveHead& head_in) {
  if (!(head_in.bead.width > 0) || !(head_in.bead.height > 0))
    throw std::invalid_argument("deposition_path: head '" + head_in.name + "' needs a positive bead width and height");
  config::AdditiveHead head = head_in;
  if (!(head.layer_height > 0)) head.layer_height = config::kDefaultLayerHeightFraction * head.bead.height;
  if (!(head.hatch_spacing > 0)) head.hatch_spacing = config::kDefaultHatchSpacingFraction * head.bead.width;
  if (!(head.feed > 0)) head.feed = 1000;
  head.travel_clearance = std::max(0.0, head.travel_clearance);
  return head;
}

// The state of one deposition toolpath while it is built, in the work frame: the
// parameters, the per-column tops of the build, and where the head is.
class DepositionBuilder {
 public:
  DepositionBuilder(const config::AdditiveHead& head, const DepositionOptions& options, Toolpath& path)
      : head_(head), options_(options), path_(path) {}

  // The layers of `roi_all` less `existing` (both work frame, one lattice); `counted`: the
  // part of the ROI the plan counts on (DepositionOptions::counted_on, work frame) or null.
  void run(const Solid& roi_all, const Solid& existing, const Solid* counted);

 private:
  double face(int k) const { return oz_ + k * h_; }  // bottom face of voxel layer k
  void take_parameters();
  void start_columns(const Solid& existing, const IndexBox& roi_box, const IndexBox& existing_box);
  void deposit_layer(int layer, double zb);
  // The ROI's voxel layers whose centres lie in the band [zb, zb + layer_height); `k` the highest.
  SliceMask layer_region(const Solid& solid, double zb, int& k) const;
  void drop_blocked(SliceMask& region, int k, int layer, double zb);
  void drop_overhangs(SliceMask& region, int layer, double zb);
  std::vector<Pass> passes_of(const SliceMask& region, const SliceMask& wall, int layer, double angle, double zb,
                              const TipKeepOut* within);
  // DepositionOptions::near_net_design: where the layer's bead axes may go, and the passes
  // kept there.
  std::optional<TipKeepOut> near_net_region(double zb) const;
  // Its contour's axes: the design's sections at near_net_section_heights.
  TipKeepOut near_net_contour_axes(double zb) const;
  void keep_within(const TipKeepOut& inside, std::vector<Pass>& contour, std::vector<Pass>& rasters) const;
  void keep_pieces_within(const TipKeepOut& inside, std::vector<Pass>& rasters) const;
  // How far sideways a pass lays material at every voxel centre of the band at zb.
  double cover_of(double zb) const;
  void finish();

  double corridor_top(Vec2 a, Vec2 b) const;
  double footprint_top(Vec2 p) const;
  bool touches(const Pass& p, const SliceMask& mask) const;
  bool body_meets_material(const Pass& p, double zb) const;
  double clear_height(Vec2 p, double z) const { return std::max(z, footprint_top(p) + gap_); }
  void move(MoveKind kind, Vec3 to, double feed, bool on, std::string comment = {});
  void travel_to(Vec2 p, double z);

  config::AdditiveHead head_;
  const DepositionOptions& options_;
  Toolpath& path_;
  // The frame and the material.
  geometry::Lattice lattice_;
  double h_ = 1, oz_ = 0;
  Solid roi_;
  Solid existing_;   // material present before the action
  const Solid* counted_ = nullptr;  // DepositionOptions::counted_on in the work frame
  IndexBox window_;  // the columns: ROI and existing material, with room for the nozzle
  std::vector<int> existing_top_index_;
  ColumnMap existing_top_, deposited_top_, travel_top_;
  SliceMask empty_mask_;
  // Parameters, mm.
  double lh_ = 0, s_ = 0, w_ = 0, travel_ = 0, inset_ = 0, min_length_ = 0, support_gap_ = 0, reach_ = 0, gap_ = 0,
         corridor_ = 0, plate_z_ = 0, z0_ = 0, z_top_ = 0, safe_z_ = 0;
  double top_drop_ = 0;  // mm a near-net deposit's last layer is laid under its band
  std::vector<double> angles_;
  instruments::Bead bead_;
  // Emission state.
  bool started_ = false;
  Vec3 at_{};
  int warnings_overhang_ = 0, dropped_total_ = 0, out_of_reach_total_ = 0, warnings_uncounted_ = 0, body_skipped_ = 0;
  double overhang_area_total_ = 0, uncounted_area_total_ = 0;
};

void DepositionBuilder::run(const Solid& roi_all, const Solid& existing, const Solid* counted) {
  counted_ = counted;
  lattice_ = roi_all.lattice();
  h_ = lattice_.voxel_size;
  oz_ = lattice_.origin.z;
  // Material already there is not deposited again.
  roi_ = existing.empty() ? roi_all : geometry::subtract(roi_all, existing);
  existing_ = existing;
  const IndexBox roi_box = roi_.bounding_box();
  const IndexBox existing_box = existing.bounding_box();
  travel_ = head_.travel_clearance;
  if (roi_box.empty()) {
    path_.safe_z = (existing_box.empty() ? oz_ : face(existing_box.hi.z)) + travel_;
    path_.warnings.push_back("nothing to deposit: the region of influence is empty" +
                             std::string(roi_all.empty() ? "" : " (all of it is existing material)"));
    return;
  }
  take_parameters();
  start_columns(existing, roi_box, existing_box);
  for (int layer = 0;; ++layer) {
    const double zb = z0_ + layer * lh_;
    if (zb >= z_top_ - 1e-9) break;
    deposit_layer(layer, zb);
  }
  finish();
}

void DepositionBuilder::take_parameters() {
  lh_ = head_.layer_height, s_ = head_.hatch_spacing, w_ = head_.bead.width;
  inset_ = options_.edge_inset.value_or(w_ / 2);
  min_length_ = options_.min_segment_length.value_or(w_);
  // The simulator rests a bead on material in the voxel layer just under its bottom
  // (sim/material.cpp): a column top within half a voxel below the layer's bottom. A
  // layer's worth of gap would count the layer before last as support.
  support_gap_ = options_.support_gap.value_or(h_ / 2);
  // A bead is held where its axis lies within the head's one-layer reach of what is below
  // (instruments/support_rule.hpp, as the simulator judges it), and never more than half a
  // bead beyond it.
  reach_ = options_.overhang_reach.value_or(std::min(w_ / 2, instruments::support_rule(head_.support, h_).reach(1) * h_));
  gap_ = std::max(0.0, options_.approach_gap);
  corridor_ = std::max(w_ / 2, head_.nozzle ? head_.nozzle->diameter / 2 : 0.0);
  bead_ = instruments::bead_of(head_);
  angles_ = options_.raster_angles_deg.empty() ? std::vector<double>{0.0} : options_.raster_angles_deg;
}

// The column maps over the window, the build plate and safe_z.
void DepositionBuilder::start_columns(const Solid& existing, const IndexBox& roi_box, const IndexBox& existing_box) {
  const IndexBox material_box = geometry::box_union(roi_box, existing_box);
  const int margin = int(std::ceil(corridor_ / h_)) + 2;
  window_ = {{material_box.lo.x - margin, material_box.lo.y - margin, material_box.lo.z},
             {material_box.hi.x + margin, material_box.hi.y + margin, material_box.hi.z}};
  existing_top_index_ = column_top_indices(existing, window_);
  existing_top_ = ColumnMap(window_, kNone);
  deposited_top_ = ColumnMap(window_, kNone);
  travel_top_ = ColumnMap(window_, kNone);
  double highest_existing = kNone;
  for (std::size_t i = 0; i < existing_top_.values.size(); ++i)
    if (existing_top_index_[i] != kNoVoxel) {
      existing_top_.values[i] = face(existing_top_index_[i] + 1);
      highest_existing = std::max(highest_existing, existing_top_.values[i]);
    }
  travel_top_.values = existing_top_.values;
  plate_z_ = options_.build_plate_z.value_or(face(material_box.lo.z));
  empty_mask_ = SliceMask(window_.lo.x, window_.lo.y, window_.hi.x - window_.lo.x, window_.hi.y - window_.lo.y);

  z0_ = face(roi_box.lo.z), z_top_ = face(roi_box.hi.z);
  // A near-net deposit's layers end on its top: as many as the head's layer height needs,
  // a little thinner each, and the last laid lower, so that its crests stand over the top
  // by half the dip where two tracks meet, not by the beads' overlap or most of a layer.
  if (options_.near_net_design && z_top_ > z0_) {
    lh_ = (z_top_ - z0_) / std::ceil((z_top_ - z0_) / lh_ - 1e-9);
    top_drop_ = std::max(0.0, head_.bead.height - lh_ - instruments::bead_top_dip(bead_, s_) / 2);
  }
  safe_z_ = std::max({highest_existing, z_top_, z0_ + std::ceil((z_top_ - z0_) / lh_) * lh_}) +
            std::max(head_.bead.height, 0.0) + travel_;
  path_.safe_z = safe_z_;
}

// The highest material top of any column within the corridor of the straight travel.
double DepositionBuilder::corridor_top(Vec2 a, Vec2 b) const {
  const double reach_mm = corridor_ + h_ * std::numbers::sqrt2 / 2;
  const int x0 = int(std::floor((std::min(a.x, b.x) - reach_mm - lattice_.origin.x) / h_));
  const int x1 = int(std::floor((std::max(a.x, b.x) + reach_mm - lattice_.origin.x) / h_));
  const int y0 = int(std::floor((std::min(a.y, b.y) - reach_mm - lattice_.origin.y) / h_));
  const int y1 = int(std::floor((std::max(a.y, b.y) + reach_mm - lattice_.origin.y) / h_));
  const double abx = b.x - a.x, aby = b.y - a.y, ab2 = abx * abx + aby * aby;
  double top = kNone;
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) {
      const double v = travel_top_.at(x, y);
      if (v <= top) continue;
      const double cx = lattice_.origin.x + (x + 0.5) * h_, cy = lattice_.origin.y + (y + 0.5) * h_;
      double t = ab2 > 0 ? ((cx - a.x) * abx + (cy - a.y) * aby) / ab2 : 0;
      t = std::clamp(t, 0.0, 1.0);
      const double dx = cx - (a.x + t * abx), dy = cy - (a.y + t * aby);
      if (dx * dx + dy * dy <= reach_mm * reach_mm) top = v;
    }
  return top;
}

// The highest material under the bead's footprint at p (columns whose centres lie within
// half a bead width): a head whose bead bottom is above it by approach_gap clears
// everything a bead there could touch.
double DepositionBuilder::footprint_top(Vec2 p) const {
  const double r = w_ / 2;
  const int x0 = int(std::floor((p.x - r - lattice_.origin.x) / h_)), x1 = int(std::floor((p.x + r - lattice_.origin.x) / h_));
  const int y0 = int(std::floor((p.y - r - lattice_.origin.y) / h_)), y1 = int(std::floor((p.y + r - lattice_.origin.y) / h_));
  double top = kNone;
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) {
      const double cx = lattice_.origin.x + (x + 0.5) * h_ - p.x, cy = lattice_.origin.y + (y + 0.5) * h_ - p.y;
      if (cx * cx + cy * cy <= r * r + 1e-9) top = std::max(top, travel_top_.at(x, y));
    }
  return top;
}

// Whether the pass runs through a cell of `mask` (sampled every half voxel).
bool DepositionBuilder::touches(const Pass& p, const SliceMask& mask) const {
  for (std::size_t i = 0; i + 1 < p.points.size(); ++i) {
    const Vec2 a = p.points[i], b = p.points[i + 1];
    const int steps = 1 + int(std::ceil(std::hypot(b.x - a.x, b.y - a.y) / (h_ / 2)));
    for (int s = 0; s <= steps; ++s) {
      const double f = double(s) / steps;
      const int x = int(std::floor((a.x + f * (b.x - a.x) - lattice_.origin.x) / h_));
      const int y = int(std::floor((a.y + f * (b.y - a.y) - lattice_.origin.y) / h_));
      if (mask.at(x, y)) return true;
    }
  }
  return false;
}

// Whether material within the nozzle's radius of the pass stands above the body's tip
// (stand-off over the layer's bottom) anywhere along it.
bool DepositionBuilder::body_meets_material(const Pass& p, double zb) const {
  const double tip = zb + head_.nozzle->standoff;
  for (std::size_t i = 0; i + 1 < p.points.size(); ++i)
    if (corridor_top(p.points[i], p.points[i + 1]) > tip + 1e-9) return true;
  return false;
}

void DepositionBuilder::move(MoveKind kind, Vec3 to, double feed, bool on, std::string comment) {
  PathMove m;
  m.kind = kind;
  m.to = to;
  m.feed = feed;
  m.process_on = on;
  m.comment = std::move(comment);
  path_.moves.push_back(std::move(m));
  at_ = to;
}

// Gets to the start of a pass at height z, lifted over the material on the way. Near the
// work the head moves at feed: out of the bead just laid, and down the last approach_gap
// onto the surface (neighbouring beads of the layer stand a bead height above it); rapids
// only where the bead could touch nothing.
void DepositionBuilder::travel_to(Vec2 p, double z) {
  const double stop = std::min(safe_z_, clear_height(p, z));
  if (!started_) {
    path_.start = {p.x, p.y, safe_z_};
    move(MoveKind::Rapid, path_.start, 0, false, "above the first pass");
    started_ = true;
  } else {
    const double out = std::min(safe_z_, clear_height({at_.x, at_.y}, at_.z));
    if (at_.z < out) move(MoveKind::Feed, {at_.x, at_.y, out}, head_.feed, false, "up from the bead");
    const double lift =
        std::min(safe_z_, std::max({at_.z, stop, z + travel_, corridor_top({at_.x, at_.y}, p) + travel_}));
    if (at_.z < lift) move(MoveKind::Rapid, {at_.x, at_.y, lift}, 0, false);
    move(MoveKind::Rapid, {p.x, p.y, at_.z}, 0, false);
  }
  if (at_.z > stop) move(MoveKind::Rapid, {p.x, p.y, stop}, 0, false);
  if (at_.z > z) move(MoveKind::Feed, {p.x, p.y, z}, head_.feed, false, "down onto the surface");
}

// Every ROI voxel belongs to exactly one layer. A band thinner than a voxel may hold no
// centre: it takes the layer its middle lies in, so no layer of the build is skipped.
SliceMask DepositionBuilder::layer_region(const Solid& solid, double zb, int& k) const {
  int k_lo = int(std::ceil((zb - oz_) / h_ - 0.5 - 1e-9));
  int k_hi = int(std::ceil((zb + lh_ - oz_) / h_ - 0.5 - 1e-9)) - 1;
  if (k_hi < k_lo) k_lo = k_hi = int(std::floor((zb + lh_ / 2 - oz_) / h_));
  SliceMask region = slice_of(solid, k_lo, window_);
  for (int kk = k_lo + 1; kk <= k_hi; ++kk) region |= slice_of(solid, kk, window_);
  k = k_hi;
  return region;
}

// Columns with existing material above this layer cannot be reached from +Z.
void DepositionBuilder::drop_blocked(SliceMask& region, int k, int layer, double zb) {
  SliceMask blocked = empty_mask_;
  for (int y = window_.lo.y; y < window_.hi.y; ++y)
    for (int x = window_.lo.x; x < window_.hi.x; ++x)
      if (region.at(x, y) &&
          existing_top_index_[std::size_t(y - window_.lo.y) * std::size_t(existing_top_.nx) + std::size_t(x - window_.lo.x)] > k)
        blocked.set(x, y);
  if (blocked.empty()) return;
  region = region.without(blocked);
  if (counted_) {
    int band_top = 0;
    const SliceMask uncounted = blocked.without(layer_region(*counted_, zb, band_top));
    if (!uncounted.empty()) {
      const double area = double(uncounted.count()) * h_ * h_;
      uncounted_area_total_ += area;
      if (++warnings_uncounted_ <= kMaxWarningsPerKind)
        path_.warnings.push_back("layer " + std::to_string(layer + 1) + " at z=" + mm(zb) + " mm: " + mm(area) +
                                 " mm^2 that earlier actions were to lay lie under existing material; left out");
      blocked = blocked.without(uncounted);
    }
  }
  const std::int64_t n = blocked.count();
  if (n == 0) return;
  const double area = double(n) * h_ * h_;
  // The part would lack this deposit: a defect (export refuses, validation rejects).
  const CellBox b = cell_bounds(blocked);
  const Vec3 middle{lattice_.origin.x + 0.5 * (b.x0 + b.x1) * h_, lattice_.origin.y + 0.5 * (b.y0 + b.y1) * h_, zb};
  path_.defects.push_back({"layer_skipped", "layer " + std::to_string(layer + 1) + " at z=" + mm(zb) + " mm: " +
                                                mm(area) + " mm^2 lie under existing material, out of reach from "
                                                "the approach side; skipped",
                           middle});
}

// Overhangs: deposit with nothing (existing, deposited, plate) close enough below is not
// laid: a bead over air falls (docs/support.md), so the head never deposits there; what the
// part then lacks is the plan's to answer for (validation compares the part made with the
// design). The layers above see no material there and are cut back in turn.
void DepositionBuilder::drop_overhangs(SliceMask& region, int layer, double zb) {
  SliceMask supported = empty_mask_;
  const bool on_plate = zb - plate_z_ <= support_gap_ + 1e-9;
  for (int y = window_.lo.y; y < window_.hi.y; ++y)
    for (int x = window_.lo.x; x < window_.hi.x; ++x) {
      const double below = std::max(existing_top_.at(x, y), deposited_top_.at(x, y));
      if (on_plate || (below > kNone && below >= zb - support_gap_ - 1e-9 && below <= zb + lh_)) supported.set(x, y);
    }
  const SliceMask overhang = region.without(grow_by_disc(supported, reach_ / h_));
  const std::int64_t n = overhang.count();
  if (n == 0) return;
  region = region.without(overhang);
  const CellBox b = cell_bounds(overhang);
  const double area = double(n) * h_ * h_;
  overhang_area_total_ += area;
  if (++warnings_overhang_ <= kMaxWarningsPerKind)
    path_.warnings.push_back("overhang: layer " + std::to_string(layer + 1) + " at z=" + mm(zb) + " mm has " + mm(area) +
                             " mm^2 with nothing below it, not deposited, within x " + mm(lattice_.origin.x + b.x0 * h_) +
                             ".." + mm(lattice_.origin.x + b.x1 * h_) + ", y " + mm(lattice_.origin.y + b.y0 * h_) +
                             ".." + mm(lattice_.origin.y + b.y1 * h_) + " mm (work frame)");
}

// The layer's passes in order: rasters, and the contour before or after them.
// The bead narrows above its middle (instruments::bead_half_width_at): the band's highest
// voxel centre below the next layer's bottom is the one it reaches least far. A band
// that holds no centre lays the voxel above it, which the next layer lays again lower in
// its bead: that layer's contour answers for it.
double DepositionBuilder::cover_of(double zb) const {
  double cover = w_ / 2;
  const int k_lo = int(std::ceil((zb - oz_) / h_ - 0.5 - 1e-9)), k_hi = int(std::ceil((zb + lh_ - oz_) / h_ - 0.5 - 1e-9)) - 1;
  for (int k = k_lo; k <= k_hi; ++k) cover = std::min(cover, instruments::bead_half_width_at(bead_, oz_ + (k + 0.5) * h_ - zb));
  return cover;
}

std::vector<Pass> DepositionBuilder::passes_of(const SliceMask& region, const SliceMask& wall, int layer, double angle,
                                               double zb, const TipKeepOut* within) {
  const bool reverse_start = (layer / int(angles_.size())) % 2 == 1;
  std::vector<Pass> contour;
  RasterResult infill;
  if (options_.contour != ContourPass::None) {
    int out_of_reach = 0;
    for (auto& chain : voxel_contour(region, wall, lattice_, inset_, min_length_, {cover_of(zb), w_ / 2}, out_of_reach))
      contour.push_back({std::move(chain)});
    if (!contour.empty()) out_of_reach_total_ += out_of_reach;
  }
  SliceMask filled = contour.empty() ? SliceMask() : shrink_by_disc(region, s_ / h_);
  // A near-net layer's contour on the exact section (toolpaths/near_net_contour.hpp), with
  // the rasters beside it running on towards it: it may lie farther out than the voxel
  // contour, and rasters that stop where they stopped for that one leave voids between
  // their ends and it. They stop a bead less a hatch spacing short of its axis, and
  // 15 % of a bead less again: a raster along it closer than that is left out, and the next
  // one in still overlaps its bead (by no less than the margin).
  std::vector<Pass> exact;
  std::optional<TipKeepOut> axes, rasters_within;
  const double slack = std::max(0.0, options_.near_net_slack);
  const NearNetBead bead{w_ / 2, w_ / 2 - slack, w_ / 2 + slack, min_length_};
  if (within && !contour.empty()) {
    std::vector<std::vector<Vec2>> chains;
    for (Pass& p : contour) chains.push_back(std::move(p.points));
    axes = near_net_contour_axes(zb);
    NearNetContour c = near_net_contour(*axes, region, chains, lattice_, bead);
    contour.clear();
    for (auto& line : c.voxel) contour.push_back({std::move(line)});
    for (auto& line : c.exact) exact.push_back({std::move(line)});
    if (!exact.empty()) {
      SliceMask beside = grow_by_disc(c.exact_cells, (s_ + w_) / h_);
      beside &= region;
      filled |= beside;
      rasters_within = axes->grown(-std::max(0.0, 0.85 * w_ - s_));
    }
  }
  if (!contour.empty() || !exact.empty()) {
    infill = raster_layer(filled, lattice_, angle, s_, min_length_, inset_, reverse_start);
  } else {
    // No contour fits (a region narrower than a bead everywhere): rasters alone, whose
    // segments along the region may still fit, and whose dropped ones are counted.
    infill = raster_layer(region, lattice_, angle, s_, min_length_, inset_, reverse_start, &wall);
  }
  dropped_total_ += infill.dropped;
  if (rasters_within) {
    keep_pieces_within(*rasters_within, infill.passes);
    for (auto& line : near_net_gap_loops(*axes, region, lattice_, bead, s_)) exact.push_back({std::move(line)});
  }
  if (within) keep_within(*within, contour, infill.passes);
  contour.insert(contour.begin(), exact.begin(), exact.end());
  std::vector<Pass> passes;
  if (options_.contour == ContourPass::BeforeInfill) passes = contour;
  passes.insert(passes.end(), infill.passes.begin(), infill.passes.end());
  if (options_.contour == ContourPass::AfterInfill) passes.insert(passes.end(), contour.begin(), contour.end());
  return passes;
}

// Where a near-net layer's bead axes may go: within the design's sections from the band's
// bottom to its top, shrunk by half a bead less the slack; none without a design or where
// no axis fits.
std::optional<TipKeepOut> DepositionBuilder::near_net_region(double zb) const {
  if (!options_.near_net_design) return std::nullopt;
  constexpr double kInside = 1e-6;  // mm off the band's faces, where a flat face of the design may lie
  TipKeepOut inside = section_shrunk(*options_.near_net_design, {zb + kInside, zb + lh_ - kInside},
                                     w_ / 2 - std::max(0.0, options_.near_net_slack));
  if (inside.empty()) return std::nullopt;
  return inside;
}

TipKeepOut DepositionBuilder::near_net_contour_axes(double zb) const {
  return section_shrunk(*options_.near_net_design,
                        near_net_section_heights(*options_.near_net_design, zb, lh_, head_.bead.height, lattice_),
                        w_ / 2 - std::max(0.0, options_.near_net_slack));
}

void DepositionBuilder::keep_within(const TipKeepOut& inside, std::vector<Pass>& contour, std::vector<Pass>& rasters) const {
  for (Pass& p : contour)
    for (Vec2& q : p.points) {
      if (inside.contains(q)) continue;
      const Vec2 edge = inside.nearest_on_boundary(q);
      if (std::hypot(edge.x - q.x, edge.y - q.y) <= h_) q = edge;
    }
  for (Pass& p : contour)  // points moved onto one another
    p.points.erase(std::unique(p.points.begin(), p.points.end(),
                               [](Vec2 a, Vec2 b) { return std::hypot(a.x - b.x, a.y - b.y) < 1e-9; }),
                   p.points.end());
  keep_pieces_within(inside, rasters);
}

void DepositionBuilder::keep_pieces_within(const TipKeepOut& inside, std::vector<Pass>& rasters) const {
  std::vector<Pass> kept;
  for (const Pass& p : rasters) {
    // A raster kept whole stays, however short its inset left it; a piece cut off by the
    // wall is as long as a bead at least.
    const Vec2 a0 = p.points.front(), b0 = p.points.back();
    const double whole = std::hypot(b0.x - a0.x, b0.y - a0.y);
    for (const auto& [a, b] : inside.pieces_inside(a0, b0))
      if (std::hypot(b.x - a.x, b.y - a.y) >= std::min(whole, min_length_) - 1e-9) kept.push_back({{a, b}});
  }
  rasters = std::move(kept);
}

void DepositionBuilder::deposit_layer(int layer, double zb) {
  // The height the layer is laid at: its band's bottom, lower for a near-net deposit's last.
  const double zp = zb + lh_ >= z_top_ - 1e-9 ? zb - top_drop_ : zb;
  int k = 0;
  SliceMask region = layer_region(roi_, zb, k);
  if (region.empty()) return;
  drop_blocked(region, k, layer, zb);
  if (!region.empty()) drop_overhangs(region, layer, zb);
  if (region.empty()) return;
  // This layer's beads count at their full height for travels from its first pass on.
  for (int y = window_.lo.y; y < window_.hi.y; ++y)
    for (int x = window_.lo.x; x < window_.hi.x; ++x)
      if (region.at(x, y)) travel_top_.ref(x, y) = std::max(travel_top_.at(x, y), zp + head_.bead.height);

  const double angle = angles_[std::size_t(layer) % angles_.size()];
  bool first_of_layer = true;
  const SliceMask wall = existing_.empty() ? empty_mask_ : slice_of(existing_, k, window_);
  // A pass the plan does not count on this action for (earlier actions were to lay it) is
  // left out where the nozzle body over it would meet material beside it: the machine
  // would stop there (body_collision), and the part is judged by what it lacks instead.
  // The passes the plan counts on are the planner's to keep clear (planner/atoms/deposit_reach.hpp).
  const bool check_body = counted_ && head_.nozzle;
  int counted_top = 0;
  const SliceMask counted_here = check_body ? layer_region(*counted_, zb, counted_top) : empty_mask_;
  const std::optional<TipKeepOut> within = near_net_region(zb);
  for (const Pass& p : passes_of(region, wall, layer, angle, zb, within ? &*within : nullptr)) {
    if (check_body && !touches(p, counted_here) && body_meets_material(p, zp)) {
      ++body_skipped_;
      continue;
    }
    travel_to(p.points.front(), zp);
    for (std::size_t i = 1; i < p.points.size(); ++i) {
      std::string comment;
      if (first_of_layer) comment = "layer " + std::to_string(layer + 1) + " z=" + mm(zp) + " raster " + mm(angle) + " deg";
      first_of_layer = false;
      move(MoveKind::Feed, {p.points[i].x, p.points[i].y, zp}, head_.feed, true, std::move(comment));
    }
  }
  // The layer is down: layer_height of material on its region, as far as its beads reach
  // (a near-net layer's beads stop on the design's walls: the next layer is supported by
  // what they laid, as the simulator holds it, not by the voxels past them).
  const SliceMask laid = within ? cells_inside(within->grown(w_ / 2), empty_mask_, lattice_) : region;
  for (int y = window_.lo.y; y < window_.hi.y; ++y)
    for (int x = window_.lo.x; x < window_.hi.x; ++x)
      if (region.at(x, y) && laid.at(x, y)) deposited_top_.ref(x, y) = std::max(deposited_top_.at(x, y), zb + lh_);
}

// Up and clear of the part, and the summaries of the warnings.
void DepositionBuilder::finish() {
  if (started_) {
    const double out = std::min(safe_z_, clear_height({at_.x, at_.y}, at_.z));
    if (at_.z < out) move(MoveKind::Feed, {at_.x, at_.y, out}, head_.feed, false, "up from the bead");
    move(MoveKind::Rapid, {at_.x, at_.y, safe_z_}, 0, false, "clear of the part");
  }
  if (warnings_overhang_ > kMaxWarningsPerKind)
    path_.warnings.push_back("overhang: " + std::to_string(warnings_overhang_) + " layers in all, " +
                             mm(overhang_area_total_) + " mm^2 with nothing below it, not deposited");
  if (warnings_uncounted_ > kMaxWarningsPerKind)
    path_.warnings.push_back("under existing material: " + std::to_string(warnings_uncounted_) + " layers in all, " +
                             mm(uncounted_area_total_) + " mm^2 that earlier actions were to lay, left out");
  if (body_skipped_ > 0)
    path_.warnings.push_back(std::to_string(body_skipped_) + " passes that earlier actions were to lay left out: the " +
                             "nozzle body over them would meet material beside them");
  if (out_of_reach_total_ > 0)
    // Counted at the band's highest voxel centre: lower voxels, where the bead is wider,
    // may still be laid. Short: warnings become program comments.
    path_.warnings.push_back(std::to_string(out_of_reach_total_) + " edge cells the contour may not reach without " +
                             "laying beyond the region");
  if (dropped_total_ > 0)
    path_.warnings.push_back(std::to_string(dropped_total_) + " raster segments shorter than " + mm(min_length_) +
                             " mm dropped (narrow parts of the region stay unfilled)");
  if (!started_) path_.warnings.push_back("no deposition segment: every part of the region is narrower than a bead");
}

}  // namespace

Toolpath deposition_path(const Solid& roi_part, const Solid& existing_part, const config::AdditiveHead& head_in,
                         const config::Setup& setup, const DepositionOptions& options) {
  const config::AdditiveHead head = with_defaults(head_in);
  const bool has_existing = !existing_part.empty();
  if (has_existing && !(existing_part.lattice() == roi_part.lattice()))
    throw std::invalid_argument("deposition_path: the ROI and the existing material are on different lattices");

  Toolpath path;
  path.process = Process::Deposition;
  path.instrument = head.name;
  path.tool_number = instruments::head_tool_number(head, options.fallback_tool_number);
  path.setup = setup.name;
  if (options.counted_on && !(options.counted_on->lattice() == roi_part.lattice()))
    throw std::invalid_argument("deposition_path: the ROI and the part counted on are on different lattices");
  const Solid roi_all = part_to_work(roi_part, setup.approach);
  const Solid existing = has_existing ? part_to_work(existing_part, setup.approach) : Solid(roi_all.lattice(), {});
  const std::optional<Solid> counted =
      options.counted_on ? std::optional<Solid>(part_to_work(*options.counted_on, setup.approach)) : std::nullopt;
  DepositionBuilder(head, options, path).run(roi_all, existing, counted ? &*counted : nullptr);
  return path;
}

}  // namespace hybridctl::toolpaths
