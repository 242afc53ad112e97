#include "toolpaths/deposition_path.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

#include "instruments/bead.hpp"
#include "toolpaths/setup_frame.hpp"
#include "toolpaths/slices.hpp"

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

struct Vec2 {
  double x = 0, y = 0;
};

std::string mm(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f", v);
  return buf;
}

// A polyline of deposition at one height.
struct Pass {
  std::vector<Vec2> points;
};

// The per-column state of the build, over an XY window of cells.
struct ColumnMap {
  IndexBox window;
  int nx = 0, ny = 0;
  std::vector<double> values;

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

RasterResult raster_layer(const SliceMask& region, const geometry::Lattice& lattice, double angle_deg, double spacing,
                          double min_length, double inset, bool reverse_start) {
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
    std::vector<std::pair<double, double>> intervals;
    double t = t0, open_at = 0;
    bool open = false;
    while (t < t1) {
      const bool in = region.at(ix, iy);
      if (in && !open) {
        open = true;
        open_at = t;
      } else if (!in && open) {
        open = false;
        intervals.push_back({open_at, t});
      }
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
    if (open) intervals.push_back({open_at, t1});
    std::vector<Pass> line;
    for (auto [ta, tb] : intervals) {
      const double length = tb - ta;
      if (length < min_length - 1e-9) {
        ++out.dropped;
        continue;
      }
      const double e = std::min(inset, std::max(0.0, 0.5 * (length - h)));
      const Vec2 p{n.x * u + d.x * (ta + e), n.y * u + d.y * (ta + e)};
      const Vec2 q{n.x * u + d.x * (tb - e), n.y * u + d.y * (tb - e)};
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

// Contour chains: the boundary cells of the region shrunk by `inset`, as polylines.
std::vector<Pass> contour_layer(const SliceMask& region, const geometry::Lattice& lattice, double inset,
                                double min_length) {
  const double h = lattice.voxel_size;
  const SliceMask inner = shrink_by_disc(region, inset / h);
  std::vector<Pass> out;
  for (const auto& chain : trace_chains(boundary_cells(inner))) {
    Pass p;
    double length = 0;
    for (std::size_t i = 0; i < chain.size(); ++i) {
      const Vec2 c{lattice.origin.x + (chain[i].x + 0.5) * h, lattice.origin.y + (chain[i].y + 0.5) * h};
      if (i > 0) length += std::hypot(c.x - p.points.back().x, c.y - p.points.back().y);
      // Drop the middle point of three collinear ones.
      if (p.points.size() >= 2) {
        const Vec2 a = p.points[p.points.size() - 2], b = p.points.back();
        const double cross = (b.x - a.x) * (c.y - b.y) - (b.y - a.y) * (c.x - b.x);
        const double dot = (b.x - a.x) * (c.x - b.x) + (b.y - a.y) * (c.y - b.y);
        if (std::abs(cross) < 1e-12 && dot > 0) p.points.pop_back();
      }
      p.points.push_back(c);
    }
    if (p.points.size() >= 2 && length >= min_length - 1e-9) out.push_back(std::move(p));
  }
  return out;
}

}  // namespace

Toolpath deposition_path(const Solid& roi_part, const Solid& existing_part, const config::AdditiveHead& head_in,
                         const config::Setup& setup, const DepositionOptions& options) {
  if (!(head_in.bead.width > 0) || !(head_in.bead.height > 0))
    throw std::invalid_argument("deposition_path: head '" + head_in.name + "' needs a positive bead width and height");
  // The machine file's documented defaults for a head built by hand with them unset.
  config::AdditiveHead head = head_in;
  if (!(head.layer_height > 0)) head.layer_height = config::kDefaultLayerHeightFraction * head.bead.height;
  if (!(head.hatch_spacing > 0)) head.hatch_spacing = config::kDefaultHatchSpacingFraction * head.bead.width;
  if (!(head.feed > 0)) head.feed = 1000;
  head.travel_clearance = std::max(0.0, head.travel_clearance);
  const bool has_existing = !existing_part.empty();
  if (has_existing && !(existing_part.lattice() == roi_part.lattice()))
    throw std::invalid_argument("deposition_path: the ROI and the existing material are on different lattices");

  Toolpath path;
  path.process = Process::Deposition;
  path.instrument = head.name;
  path.tool_number = instruments::head_tool_number(head, options.fallback_tool_number);
  path.setup = setup.name;

  const Solid roi_all = part_to_work(roi_part, setup.approach);
  const Solid existing = has_existing ? part_to_work(existing_part, setup.approach) : Solid(roi_all.lattice(), {});
  const geometry::Lattice& lattice = roi_all.lattice();
  const double h = lattice.voxel_size, oz = lattice.origin.z;
  auto face = [&](int k) { return oz + k * h; };  // bottom face of voxel layer k
  // Material already there is not deposited again.
  const Solid roi = has_existing ? geometry::subtract(roi_all, existing) : roi_all;
  const IndexBox roi_box = roi.bounding_box();
  const IndexBox existing_box = existing.bounding_box();
  const double travel = head.travel_clearance;
  if (roi_box.empty()) {
    path.safe_z = (existing_box.empty() ? oz : face(existing_box.hi.z)) + travel;
    path.warnings.push_back("nothing to deposit: the region of influence is empty" +
                            std::string(roi_all.empty() ? "" : " (all of it is existing material)"));
    return path;
  }

  const double lh = head.layer_height, s = head.hatch_spacing, w = head.bead.width;
  const double inset = options.edge_inset.value_or(w / 2);
  const double min_length = options.min_segment_length.value_or(w);
  const double support_gap = options.support_gap.value_or(lh);
  const double reach = options.overhang_reach.value_or(w / 2);
  const double gap = std::max(0.0, options.approach_gap);
  const double corridor = std::max(w / 2, head.nozzle ? head.nozzle->diameter / 2 : 0.0);
  const std::vector<double> angles = options.raster_angles_deg.empty() ? std::vector<double>{0.0} : options.raster_angles_deg;

  // Columns: the ROI and existing material, with room for the nozzle's corridor.
  const IndexBox material_box = geometry::box_union(roi_box, existing_box);
  const int margin = int(std::ceil(corridor / h)) + 2;
  const IndexBox window{{material_box.lo.x - margin, material_box.lo.y - margin, material_box.lo.z},
                        {material_box.hi.x + margin, material_box.hi.y + margin, material_box.hi.z}};
  const std::vector<int> existing_top_index = column_top_indices(existing, window);
  ColumnMap existing_top(window, kNone), deposited_top(window, kNone), travel_top(window, kNone);
  double highest_existing = kNone;
  for (std::size_t i = 0; i < existing_top.values.size(); ++i)
    if (existing_top_index[i] != kNoVoxel) {
      existing_top.values[i] = face(existing_top_index[i] + 1);
      highest_existing = std::max(highest_existing, existing_top.values[i]);
    }
  travel_top.values = existing_top.values;
  const double plate_z = options.build_plate_z.value_or(face(material_box.lo.z));

  const double z0 = face(roi_box.lo.z), z_top = face(roi_box.hi.z);
  const double safe_z = std::max({highest_existing, z_top, z0 + std::ceil((z_top - z0) / lh) * lh}) +
                        std::max(head.bead.height, 0.0) + travel;
  path.safe_z = safe_z;

  // Emission state.
  bool started = false;
  Vec3 at{};
  int warnings_overhang = 0, warnings_blocked = 0, dropped_total = 0;
  double overhang_area_total = 0, blocked_area_total = 0;

  auto corridor_top = [&](Vec2 a, Vec2 b) {
    // The highest material top of any column within the corridor of the straight travel.
    const double reach_mm = corridor + h * std::numbers::sqrt2 / 2;
    const int x0 = int(std::floor((std::min(a.x, b.x) - reach_mm - lattice.origin.x) / h));
    const int x1 = int(std::floor((std::max(a.x, b.x) + reach_mm - lattice.origin.x) / h));
    const int y0 = int(std::floor((std::min(a.y, b.y) - reach_mm - lattice.origin.y) / h));
    const int y1 = int(std::floor((std::max(a.y, b.y) + reach_mm - lattice.origin.y) / h));
    const double abx = b.x - a.x, aby = b.y - a.y, ab2 = abx * abx + aby * aby;
    double top = kNone;
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        const double v = travel_top.at(x, y);
        if (v <= top) continue;
        const double cx = lattice.origin.x + (x + 0.5) * h, cy = lattice.origin.y + (y + 0.5) * h;
        double t = ab2 > 0 ? ((cx - a.x) * abx + (cy - a.y) * aby) / ab2 : 0;
        t = std::clamp(t, 0.0, 1.0);
        const double dx = cx - (a.x + t * abx), dy = cy - (a.y + t * aby);
        if (dx * dx + dy * dy <= reach_mm * reach_mm) top = v;
      }
    return top;
  };
  // The highest material under the bead's footprint at p (columns whose centres lie
  // within half a bead width): a head whose bead bottom is above it by approach_gap
  // clears everything a bead there could touch.
  auto footprint_top = [&](Vec2 p) {
    const double r = w / 2;
    const int x0 = int(std::floor((p.x - r - lattice.origin.x) / h)), x1 = int(std::floor((p.x + r - lattice.origin.x) / h));
    const int y0 = int(std::floor((p.y - r - lattice.origin.y) / h)), y1 = int(std::floor((p.y + r - lattice.origin.y) / h));
    double top = kNone;
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        const double cx = lattice.origin.x + (x + 0.5) * h - p.x, cy = lattice.origin.y + (y + 0.5) * h - p.y;
        if (cx * cx + cy * cy <= r * r + 1e-9) top = std::max(top, travel_top.at(x, y));
      }
    return top;
  };
  auto move = [&](MoveKind kind, Vec3 to, double feed, bool on, std::string comment = {}) {
    PathMove m;
    m.kind = kind;
    m.to = to;
    m.feed = feed;
    m.process_on = on;
    m.comment = std::move(comment);
    path.moves.push_back(std::move(m));
    at = to;
  };
  // Gets to the start of a pass at height z, lifted over the material on the way. Near
  // the work the head moves at feed: out of the bead just laid, and down the last
  // approach_gap onto the surface (neighbouring beads of the layer stand a bead height
  // above it); rapids only where the bead could touch nothing.
  auto clear_height = [&](Vec2 p, double z) { return std::max(z, footprint_top(p) + gap); };
  auto travel_to = [&](Vec2 p, double z) {
    const double stop = std::min(safe_z, clear_height(p, z));
    if (!started) {
      path.start = {p.x, p.y, safe_z};
      move(MoveKind::Rapid, path.start, 0, false, "above the first pass");
      started = true;
    } else {
      const double out = std::min(safe_z, clear_height({at.x, at.y}, at.z));
      if (at.z < out) move(MoveKind::Feed, {at.x, at.y, out}, head.feed, false, "up from the bead");
      const double lift =
          std::min(safe_z, std::max({at.z, stop, z + travel, corridor_top({at.x, at.y}, p) + travel}));
      if (at.z < lift) move(MoveKind::Rapid, {at.x, at.y, lift}, 0, false);
      move(MoveKind::Rapid, {p.x, p.y, at.z}, 0, false);
    }
    if (at.z > stop) move(MoveKind::Rapid, {p.x, p.y, stop}, 0, false);
    if (at.z > z) move(MoveKind::Feed, {p.x, p.y, z}, head.feed, false, "down onto the surface");
  };

  const SliceMask empty_mask(window.lo.x, window.lo.y, window.hi.x - window.lo.x, window.hi.y - window.lo.y);
  for (int layer = 0;; ++layer) {
    const double zb = z0 + layer * lh;
    if (zb >= z_top - 1e-9) break;
    // The voxel layers whose centres lie in [zb, zb + lh): every ROI voxel belongs to
    // exactly one layer. A band thinner than a voxel may hold no centre: it takes the
    // layer its middle lies in, so no layer of the build is skipped.
    int k_lo = int(std::ceil((zb - oz) / h - 0.5 - 1e-9));
    int k_hi = int(std::ceil((zb + lh - oz) / h - 0.5 - 1e-9)) - 1;
    if (k_hi < k_lo) k_lo = k_hi = int(std::floor((zb + lh / 2 - oz) / h));
    SliceMask region = slice_of(roi, k_lo, window);
    for (int kk = k_lo + 1; kk <= k_hi; ++kk) region |= slice_of(roi, kk, window);
    if (region.empty()) continue;
    const int k = k_hi;

    // Columns with existing material above this layer cannot be reached from +Z.
    SliceMask blocked = empty_mask;
    for (int y = window.lo.y; y < window.hi.y; ++y)
      for (int x = window.lo.x; x < window.hi.x; ++x)
        if (region.at(x, y) &&
            existing_top_index[std::size_t(y - window.lo.y) * std::size_t(existing_top.nx) + std::size_t(x - window.lo.x)] > k)
          blocked.set(x, y);
    if (const std::int64_t n = blocked.count(); n > 0) {
      region = region.without(blocked);
      const double area = double(n) * h * h;
      blocked_area_total += area;
      if (++warnings_blocked <= kMaxWarningsPerKind)
        path.warnings.push_back("layer " + std::to_string(layer + 1) + " at z=" + mm(zb) + " mm: " + mm(area) +
                                " mm^2 lie under existing material, out of reach from the approach side; skipped");
      if (region.empty()) continue;
    }

    // Overhangs: deposit with nothing (existing, deposited, plate) close enough below.
    SliceMask supported = empty_mask;
    const bool on_plate = zb - plate_z <= support_gap + 1e-9;
    for (int y = window.lo.y; y < window.hi.y; ++y)
      for (int x = window.lo.x; x < window.hi.x; ++x) {
        const double below = std::max(existing_top.at(x, y), deposited_top.at(x, y));
        if (on_plate || (below > kNone && below >= zb - support_gap - 1e-9 && below <= zb + lh)) supported.set(x, y);
      }
    const SliceMask overhang = region.without(grow_by_disc(supported, reach / h));
    if (const std::int64_t n = overhang.count(); n > 0) {
      const CellBox b = cell_bounds(overhang);
      const double area = double(n) * h * h;
      overhang_area_total += area;
      if (++warnings_overhang <= kMaxWarningsPerKind)
        path.warnings.push_back("overhang: layer " + std::to_string(layer + 1) + " at z=" + mm(zb) + " mm has " +
                                mm(area) + " mm^2 of deposit with nothing below it, within x " +
                                mm(lattice.origin.x + b.x0 * h) + ".." + mm(lattice.origin.x + b.x1 * h) + ", y " +
                                mm(lattice.origin.y + b.y0 * h) + ".." + mm(lattice.origin.y + b.y1 * h) +
                                " mm (work frame)");
    }

    // This layer's beads count at their full height for travels from its first pass on.
    for (int y = window.lo.y; y < window.hi.y; ++y)
      for (int x = window.lo.x; x < window.hi.x; ++x)
        if (region.at(x, y)) travel_top.ref(x, y) = std::max(travel_top.at(x, y), zb + head.bead.height);

    const double angle = angles[std::size_t(layer) % angles.size()];
    std::vector<Pass> contour, infill;
    if (options.contour != ContourPass::None) {
      contour = contour_layer(region, lattice, inset, min_length);
      RasterResult r = raster_layer(shrink_by_disc(region, s / h), lattice, angle, s, min_length, inset,
                                    (layer / int(angles.size())) % 2 == 1);
      infill = std::move(r.passes);
      dropped_total += r.dropped;
    } else {
      RasterResult r = raster_layer(region, lattice, angle, s, min_length, inset, (layer / int(angles.size())) % 2 == 1);
      infill = std::move(r.passes);
      dropped_total += r.dropped;
    }
    std::vector<Pass> passes;
    if (options.contour == ContourPass::BeforeInfill) passes = contour;
    passes.insert(passes.end(), infill.begin(), infill.end());
    if (options.contour == ContourPass::AfterInfill) passes.insert(passes.end(), contour.begin(), contour.end());

    bool first_of_layer = true;
    for (const Pass& p : passes) {
      travel_to(p.points.front(), zb);
      for (std::size_t i = 1; i < p.points.size(); ++i) {
        std::string comment;
        if (first_of_layer)
          comment = "layer " + std::to_string(layer + 1) + " z=" + mm(zb) + " raster " + mm(angle) + " deg";
        first_of_layer = false;
        move(MoveKind::Feed, {p.points[i].x, p.points[i].y, zb}, head.feed, true, std::move(comment));
      }
    }
    // The layer is down: layer_height of material on its region.
    for (int y = window.lo.y; y < window.hi.y; ++y)
      for (int x = window.lo.x; x < window.hi.x; ++x)
        if (region.at(x, y)) deposited_top.ref(x, y) = std::max(deposited_top.at(x, y), zb + lh);
  }

  if (started) {
    const double out = std::min(safe_z, clear_height({at.x, at.y}, at.z));
    if (at.z < out) move(MoveKind::Feed, {at.x, at.y, out}, head.feed, false, "up from the bead");
    move(MoveKind::Rapid, {at.x, at.y, safe_z}, 0, false, "clear of the part");
  }
  if (warnings_overhang > kMaxWarningsPerKind)
    path.warnings.push_back("overhang: " + std::to_string(warnings_overhang) + " layers in all, " +
                            mm(overhang_area_total) + " mm^2 of deposit with nothing below it");
  if (warnings_blocked > kMaxWarningsPerKind)
    path.warnings.push_back(std::to_string(warnings_blocked) + " layers in all have ROI under existing material (" +
                            mm(blocked_area_total) + " mm^2), skipped");
  if (dropped_total > 0)
    path.warnings.push_back(std::to_string(dropped_total) + " raster segments shorter than " + mm(min_length) +
                            " mm dropped (narrow parts of the region stay unfilled)");
  if (!started) path.warnings.push_back("no deposition segment: every part of the region is narrower than a bead");
  return path;
}

}  // namespace hybridctl::toolpaths
