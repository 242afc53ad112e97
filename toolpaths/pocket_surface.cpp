// Surface finishing (docs/toolpaths.md, "Surface finishing"): after the Z-levels, a ball or
// bull-nose cutter runs a zigzag raster over the faces its region lies on, the tip at the
// height where the cutter touches the design's STL (toolpaths/drop_cutter.hpp), so that a
// slope, a fillet or a dome is cut on the real surface rather than left as the levels'
// staircase.

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "geometry/morphology.hpp"
#include "geometry/sliding_extremum.hpp"
#include "geometry/voxelize.hpp"
#include "toolpaths/pocket_builder.hpp"

namespace hybridctl::toolpaths::pocket {

namespace {

// The chord between two path points may pass at most this far (mm) under the surface
// between them before the pair is refined, and a point is dropped when it lies at most
// kThinning under the chord of its neighbours (the path then stands that much higher).
constexpr double kChordGouge = 0.0005;
constexpr double kThinning = 0.002;
constexpr int kMaxRefinement = 10;
// What the roughing leaves on the design's faces for the finishing passes (mm), beyond
// what the lattice makes it leave.
constexpr double kRoughLeave = 0.01;

bool finite(const geometry::Vec3& p) { return std::isfinite(p.z); }

// The highest of `tops` (nx by ny cells, row-major) within `r` cells of each cell, square
// neighbourhood: a bound that spares the exact contact wherever it is below the tool.
// Rows, then columns, each a sliding maximum over 2r + 1 cells padded with kNoVoxel.
std::vector<int> max_within(const std::vector<int>& tops, int nx, int ny, int r) {
  const int block = 2 * r + 1;
  std::vector<int> padded, from_start, to_end;
  auto slide = [&](int n, auto&& at, auto&& put) {
    padded.assign(std::size_t(n + 2 * r), kNoVoxel);
    for (int i = 0; i < n; ++i) padded[std::size_t(i + r)] = at(i);
    from_start.resize(padded.size());
    to_end.resize(padded.size());
    const auto pick = [](int a, int b) { return std::max(a, b); };
    geometry::block_extrema(padded.data(), int(padded.size()), block, from_start.data(), to_end.data(), pick);
    for (int i = 0; i < n; ++i) put(i, geometry::window_extremum(from_start.data(), to_end.data(), i, block, pick));
  };
  std::vector<int> rows(tops.size()), out(tops.size());
  auto cell = [nx](int x, int y) { return std::size_t(y) * std::size_t(nx) + std::size_t(x); };
  for (int y = 0; y < ny; ++y)
    slide(nx, [&](int x) { return tops[cell(x, y)]; }, [&](int x, int m) { rows[cell(x, y)] = m; });
  for (int x = 0; x < nx; ++x)
    slide(ny, [&](int y) { return rows[cell(x, y)]; }, [&](int y, int m) { out[cell(x, y)] = m; });
  return out;
}

}  // namespace

void PocketBuilder::start_surface_finishing(const Solid& region, const Solid* design) {
  drop_.reset();
  if (!options_.finish_surfaces || !options_.design || options_.design->empty() || tool_.type == config::ToolType::Flat)
    return;
  if (!(options_.scallop > 0)) throw std::invalid_argument("pocket_path: the scallop height must be > 0 mm");
  if (design_.empty())
    design_ = design ? *design
                     : geometry::voxelize(geometry::TriangleMesh{*options_.design}, lattice_, "design",
                                          geometry::VoxelizeMethod::ExactScan);
  const CutterShape shape = cutter_shape(tool_);
  surface_step_over_ = std::min(step_over_, scallop_step_over(shape, options_.scallop));
  // What must stay is an obstacle on the voxels, except the design's own voxels (the
  // design is the STL, and its voxels reach up to half a voxel past it) and those beside them.
  stays_ = stays_besides_design();
  obstacle_tops_ = column_top_indices(stays_, tops_box_);
  const int tnx = tops_box_.hi.x - tops_box_.lo.x, tny = tops_box_.hi.y - tops_box_.lo.y;
  obstacle_near_ = max_within(obstacle_tops_, tnx, tny, int(std::ceil(shape.radius / h_)) + 1);
  // Material only goes from here on: the highest now bounds it for the whole run.
  material_near_ = max_within(tops_, tnx, tny, int(std::ceil(model_.max_radius / h_)) + 1);
  // The faces this region lies on: columns where a voxel of the region touches a design
  // voxel (a face's neighbour, below included), and the tip positions whose cutter reaches
  // them; within the tip domain (the ROI's, where the material is known).
  surface_domain_ = SliceMask(work_.lo.x, work_.lo.y, work_.hi.x - work_.lo.x, work_.hi.y - work_.lo.y);
  IndexBox rb = region.bounding_box();
  rb.lo.x = std::max(rb.lo.x, work_.lo.x), rb.lo.y = std::max(rb.lo.y, work_.lo.y);
  rb.hi.x = std::min(rb.hi.x, work_.hi.x), rb.hi.y = std::min(rb.hi.y, work_.hi.y);
  int lowest = rb.hi.z;  // the lowest of those voxels: no pass goes below its bottom
  bool any = false;
  for (int z = rb.lo.z; z < rb.hi.z; ++z)
    for (int y = rb.lo.y; y < rb.hi.y; ++y)
      for (int x = rb.lo.x; x < rb.hi.x; ++x) {
        if (surface_domain_.at(x, y) || !region.contains({x, y, z})) continue;
        if (design_.contains({x - 1, y, z}) || design_.contains({x + 1, y, z}) || design_.contains({x, y - 1, z}) ||
            design_.contains({x, y + 1, z}) || design_.contains({x, y, z - 1})) {
          surface_domain_.set(x, y);
          lowest = std::min(lowest, z);
          any = true;
        }
      }
  if (!any) return;
  surface_floor_ = lattice_.origin.z + lowest * h_;
  surface_domain_ = grow_by_disc(surface_domain_, shape.radius / h_ + 1);
  drop_ = std::make_shared<const DropCutter>(options_.design, shape);
  // The roughing's tips at the cell centres, kept off the STL by kRoughLeave. Between two
  // neighbouring centres the cutter stays off it too where the surface is flat or concave
  // (the drop height is then linear or convex along the step); over a convex one it may
  // dip by the step's sagitta on the surface's curvature plus the cutter's, a few
  // thousandths, which the leave covers. A wider cutter would keep the levels a voxel off
  // every steep wall, which the raster does not finish.
  const DropCutter& rough = *drop_;
  rough_tips_.assign(std::size_t(work_.hi.x - work_.lo.x) * std::size_t(work_.hi.y - work_.lo.y), -kInf);
  for (int y = work_.lo.y; y < work_.hi.y; ++y)
    for (int x = work_.lo.x; x < work_.hi.x; ++x)
      rough_tips_[std::size_t(y - work_.lo.y) * std::size_t(work_.hi.x - work_.lo.x) + std::size_t(x - work_.lo.x)] =
          rough.tip_height({lattice_.origin.x + (x + 0.5) * h_, lattice_.origin.y + (y + 0.5) * h_}) + kRoughLeave;
}

geometry::Solid PocketBuilder::stays_besides_design() const {
  // Face, edge and corner neighbours: within sqrt(3) voxels.
  const Solid beside = geometry::dilate(design_, geometry::Ball{1.75 * h_});
  return geometry::subtract(geometry::subtract(untouchable_, design_), beside);
}

SliceMask PocketBuilder::under_surface(double z) const {
  SliceMask out(work_.lo.x, work_.lo.y, work_.hi.x - work_.lo.x, work_.hi.y - work_.lo.y);
  if (!drop_) return out;
  for (int y = work_.lo.y; y < work_.hi.y; ++y)
    for (int x = work_.lo.x; x < work_.hi.x; ++x)
      if (rough_tips_[std::size_t(y - work_.lo.y) * std::size_t(work_.hi.x - work_.lo.x) + std::size_t(x - work_.lo.x)] >
          z + kHeightSlack)
        out.set(x, y);
  return out;
}

bool PocketBuilder::in_surface_domain(Point2 p) const { return surface_domain_.at(cell_of(p)); }

double PocketBuilder::surface_tip_at(Point2 p) const {
  const Cell c = cell_of(p);
  if (c.x < tops_box_.lo.x || c.y < tops_box_.lo.y || c.x >= tops_box_.hi.x || c.y >= tops_box_.hi.y) return kInf;
  const std::size_t i = std::size_t(c.y - tops_box_.lo.y) * std::size_t(tops_box_.hi.x - tops_box_.lo.x) +
                        std::size_t(c.x - tops_box_.lo.x);
  double under = drop_->tip_height(p);
  // The cutter holds nothing below its tip, the body nothing below the flutes' top: the
  // exact contacts only where something near stands that high.
  if (obstacle_near_[i] != kNoVoxel && centre_z(obstacle_near_[i]) >= under - 1e-9)
    under = std::max(under, contact_height_at(p, Part::Cutter, obstacle_tops_));
  // Over air, or hanging past an edge further down than the region goes: nothing of this
  // region to finish there, and no call to go down beside the part.
  if (under < surface_floor_ - 1e-9) return -kInf;
  if (material_near_[i] != kNoVoxel && centre_z(material_near_[i]) >= under + tool_.flute_length - model_.profile_step - 1e-6)
    under = std::max(under, contact_height_at(p, Part::Body));
  return under;
}

std::vector<geometry::Vec3> PocketBuilder::surface_line(Point2 a, Point2 b) const {
  auto at = [&](double t) {
    const Point2 q{a.x + t * (b.x - a.x), a.y + t * (b.y - a.y)};
    return Vec3{q.x, q.y, surface_tip_at(q)};
  };
  const double length = std::hypot(b.x - a.x, b.y - a.y);
  const double sample = std::min({0.25, h_ / 2, surface_step_over_});
  const int n = std::max(1, int(std::ceil(length / sample)));
  std::vector<Vec3> dense{at(0)};
  // Where the chord between two samples passes under the surface at their middle, or
  // more than kThinning over it, the middle joins the path, and so on down to
  // kMaxRefinement halvings.
  auto refine = [&](auto&& self, double t0, const Vec3& p0, double t1, const Vec3& p1, int depth) -> void {
    if (depth >= kMaxRefinement || !finite(p0) || !finite(p1)) return;
    const double tm = (t0 + t1) / 2;
    const Vec3 m = at(tm);
    // Under the chord too: in a hollow the tip's height is convex, and a chord over a
    // steep stretch of it would leave what it passes over.
    if (finite(m) && m.z <= (p0.z + p1.z) / 2 + kChordGouge && m.z >= (p0.z + p1.z) / 2 - kThinning) return;
    self(self, t0, p0, tm, m, depth + 1);
    dense.push_back(m);
    self(self, tm, m, t1, p1, depth + 1);
  };
  for (int i = 1; i <= n; ++i) {
    const double t0 = double(i - 1) / n, t1 = double(i) / n;
    const Vec3 p0 = dense.back(), p1 = at(t1);
    refine(refine, t0, p0, t1, p1, 0);
    dense.push_back(p1);
  }
  // Thinning: a point goes when every point between its kept neighbours lies under their
  // chord by at most kThinning, and none above it.
  std::vector<Vec3> out;
  std::size_t i = 0;
  while (i < dense.size()) {
    out.push_back(dense[i]);
    if (!finite(dense[i])) {
      ++i;
      continue;
    }
    std::size_t j = i + 1;
    while (j + 1 < dense.size() && finite(dense[j + 1]) && j + 1 - i <= 400) {
      const Vec3 &p = dense[i], &q = dense[j + 1];
      const double lx = q.x - p.x, ly = q.y - p.y, l2 = lx * lx + ly * ly;
      bool ok = l2 > 0;
      for (std::size_t k = i + 1; k <= j && ok; ++k) {
        const double t = ((dense[k].x - p.x) * lx + (dense[k].y - p.y) * ly) / l2;
        const double chord = p.z + t * (q.z - p.z);
        ok = dense[k].z <= chord + 1e-9 && dense[k].z >= chord - kThinning;
      }
      if (!ok) break;
      ++j;
    }
    i = j;
  }
  return out;
}

void PocketBuilder::stamp_surface_pass(const std::vector<Vec3>& pts) {
  if (pts.empty()) return;
  const CutterShape& shape = drop_->shape();
  const double R = shape.radius;
  double x0 = pts[0].x, x1 = x0, y0 = pts[0].y, y1 = y0;
  for (const Vec3& p : pts) x0 = std::min(x0, p.x), x1 = std::max(x1, p.x), y0 = std::min(y0, p.y), y1 = std::max(y1, p.y);
  const Cell lo = cell_of({x0 - R, y0 - R}), hi = cell_of({x1 + R, y1 + R});
  const int nx = hi.x - lo.x + 1, ny = hi.y - lo.y + 1;
  // Per column, the lowest point of the cutter over it along the pass, and the lowest top
  // of its flutes there: what lies between is gone (an under-estimate of what is removed,
  // so the material left may only be over-estimated).
  std::vector<double> bottom(std::size_t(nx) * std::size_t(ny), kInf), top(bottom.size(), kInf);
  auto visit = [&](const Vec3& q) {
    const Cell a = cell_of({q.x - R, q.y - R}), b = cell_of({q.x + R, q.y + R});
    for (int y = a.y; y <= b.y; ++y)
      for (int x = a.x; x <= b.x; ++x) {
        const double dx = lattice_.origin.x + (x + 0.5) * h_ - q.x, dy = lattice_.origin.y + (y + 0.5) * h_ - q.y;
        const double d = std::sqrt(dx * dx + dy * dy);
        if (d >= R - 1e-6) continue;
        const std::size_t i = std::size_t(y - lo.y) * std::size_t(nx) + std::size_t(x - lo.x);
        bottom[i] = std::min(bottom[i], q.z + shape.height_at(d));
        top[i] = std::min(top[i], q.z + tool_.flute_length);
      }
  };
  for (std::size_t s = 0; s < pts.size(); ++s) {
    const Vec3 a = pts[s], b = pts[s + 1 < pts.size() ? s + 1 : s];
    const int n = std::max(1, int(std::ceil(std::hypot(b.x - a.x, b.y - a.y) / (h_ / 2))));
    for (int k = 0; k < n; ++k) {
      const double t = double(k) / n;
      visit({a.x + t * (b.x - a.x), a.y + t * (b.y - a.y), a.z + t * (b.z - a.z)});
    }
    if (s + 1 == pts.size()) visit(b);
  }
  for (int y = lo.y; y <= hi.y; ++y)
    for (int x = lo.x; x <= hi.x; ++x) {
      const std::size_t i = std::size_t(y - lo.y) * std::size_t(nx) + std::size_t(x - lo.x);
      if (!std::isfinite(bottom[i])) continue;
      const int k0 = int(std::ceil((bottom[i] - lattice_.origin.z) / h_ - 0.5 + 1e-9));
      const int k1 = int(std::floor((top[i] - lattice_.origin.z) / h_ - 0.5 - 1e-9));
      for (int k = k0; k <= k1; ++k)
        if (remaining_.contains({x, y, k})) remaining_.set({x, y, k}, false);
    }
  refresh_tops({{lo.x, lo.y, 0}, {hi.x + 1, hi.y + 1, 1}});
}

void PocketBuilder::cut_surface_pass(const std::vector<Vec3>& pts, const std::vector<Vec3>& link) {
  spindle_ = tool_.finishing_spindle_speed();
  const Vec3 s = pts.front();
  std::vector<Vec3> swept;
  if (!link.empty()) {
    // Over the surface from where the last pass ended: the link's own drop-cutter path.
    for (std::size_t k = 1; k < link.size(); ++k)
      move(MoveKind::Feed, link[k], tool_.finishing_feed(), true, k == 1 ? "link" : "");
    swept = link;
  } else {
    retract();
    go_above(Point2{s.x, s.y}, rapid_stop_at({s.x, s.y}, s.z));
    move(MoveKind::Feed, s, tool_.plunge_feed, true, "down to the surface");
    at_level_ = true;
  }
  for (std::size_t k = 1; k < pts.size(); ++k) move(MoveKind::Feed, pts[k], tool_.finishing_feed(), true);
  swept.insert(swept.end(), pts.begin(), pts.end());
  stamp_surface_pass(swept);
  ++surface_passes_;
  spindle_ = 0;
}

// Rows along X first. Where the surface is steep across them (a fillet or a wall along
// X), the scallop between two rows widens as 1 / cos^2 of the slope across: there a second
// raster, rows along Y, follows the slope instead (docs/toolpaths.md, "Surface finishing").
void PocketBuilder::finish_surfaces() {
  if (!drop_) return;
  const CellBox box = cell_bounds(surface_domain_);
  if (box.empty()) return;
  const double step = finish_surface_rows(box, true, 0);
  // X rows `step` apart leave at most 1.5 scallops where the slope across them has a
  // cosine of at least this; steeper, the Y rows finish.
  const double steep_cos = step / scallop_step_over(drop_->shape(), 1.5 * options_.scallop);
  if (steep_cos < 1) finish_surface_rows(box, false, steep_cos);
  retract();
}

// One raster over the domain's box: rows along X (`along_x`) or along Y, `surface_step_over_`
// apart at most. With `steep_cos` > 0, only where the tip surface's slope across X rows has
// a cosine below it. Returns the step between rows.
double PocketBuilder::finish_surface_rows(const CellBox& box, bool along_x, double steep_cos) {
  const double xa = lattice_.origin.x + box.x0 * h_, xb = lattice_.origin.x + box.x1 * h_ - 1e-6;
  const double ya = lattice_.origin.y + box.y0 * h_, yb = lattice_.origin.y + box.y1 * h_ - 1e-6;
  // u along the rows, v across them.
  const double ua = along_x ? xa : ya, ub = along_x ? xb : yb, va = along_x ? ya : xa, vb = along_x ? yb : xb;
  const auto at = [&](double u, double v) { return along_x ? Point2{u, v} : Point2{v, u}; };
  const int rows = std::max(1, int(std::ceil((vb - va) / surface_step_over_))) + 1;
  const double dv = (vb - va) / (rows - 1);  // rows >= 2, and the box is not empty
  const double sample = std::min({0.25, h_ / 2, surface_step_over_});
  // Whether the tip surface at p is steep across the X rows (the cosine of its slope there
  // below steep_cos); every point when steep_cos is 0.
  const auto steep = [&](Point2 p) {
    if (!(steep_cos > 0)) return true;
    const double d = sample / 2;
    const double z0 = drop_->tip_height({p.x, p.y - d}), z1 = drop_->tip_height({p.x, p.y + d});
    if (!std::isfinite(z0) || !std::isfinite(z1)) return false;
    const double slope = (z1 - z0) / (2 * d);
    return 1 / std::sqrt(1 + slope * slope) < steep_cos;
  };
  pending_comment_ = "surface finishing: drop-cutter rows along " + std::string(along_x ? "X " : "Y ") + mm(dv) +
                     " mm apart on the STL" + (steep_cos > 0 ? ", where the surface is steep across X" : "");
  bool forward = true;
  for (int r = 0; r < rows; ++r) {
    const double v = va + r * dv;
    // The row's stretches over the domain, in the direction of travel.
    std::vector<std::pair<double, double>> stretches;
    const int n = std::max(1, int(std::ceil((ub - ua) / sample)));
    double start = 0;
    bool inside = false;
    for (int i = 0; i <= n; ++i) {
      const double u = ua + (ub - ua) * i / n;
      const bool in = in_surface_domain(at(u, v)) && steep(at(u, v));
      if (in && !inside) start = u;
      if (!in && inside) stretches.emplace_back(start, ua + (ub - ua) * (i - 1) / n);
      inside = in;
    }
    if (inside) stretches.emplace_back(start, ub);
    if (!forward) {
      std::reverse(stretches.begin(), stretches.end());
      for (auto& [a, b] : stretches) std::swap(a, b);
    }
    for (const auto& [a, b] : stretches) {
      if (std::abs(b - a) < 1e-9) continue;
      const std::vector<Vec3> line = surface_line(at(a, v), at(b, v));
      // Passes: the line's finite runs (nothing under the cutter, or no room for it, ends one).
      std::size_t i = 0;
      while (i < line.size()) {
        while (i < line.size() && !finite(line[i])) ++i;
        std::size_t j = i;
        while (j < line.size() && finite(line[j])) ++j;
        if (j >= i + 2) {
          const std::vector<Vec3> pass(line.begin() + std::ptrdiff_t(i), line.begin() + std::ptrdiff_t(j));
          // Linked over the surface when the next pass starts within two rows and the
          // drop-cutter path there holds everywhere.
          std::vector<Vec3> link;
          if (at_level_ && std::hypot(pass.front().x - at_.x, pass.front().y - at_.y) <= 2 * surface_step_over_ + 1e-9) {
            link = surface_line({at_.x, at_.y}, {pass.front().x, pass.front().y});
            if (!std::all_of(link.begin(), link.end(), finite)) link.clear();
          }
          cut_surface_pass(pass, link);
        }
        i = j;
      }
    }
    forward = !forward;
  }
  return dv;
}

}  // namespace hybridctl::toolpaths::pocket
