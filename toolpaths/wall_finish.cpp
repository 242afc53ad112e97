#include "toolpaths/wall_finish.hpp"

#include "toolpaths/mesh_sections.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "instruments/cutter.hpp"

// The keep-out region of a tool at one tip height, from the design's triangles, with
// Clipper (libpolyclipping) doing the unions and the offsets on integer coordinates.

namespace hybridctl::toolpaths {
namespace {

using geometry::Triangle;
using geometry::Vec3;
using sections::cInt;
using sections::IntPoint;
using sections::kScale;
using sections::offset;
using sections::Path;
using sections::Paths;
using sections::to_mm;
using sections::to_units;
using sections::union_of;

constexpr double kInf = std::numeric_limits<double>::infinity();
// A point this close (mm) to the boundary counts as on it.
constexpr double kOnBoundary = 1e-7;


std::vector<std::vector<Point2>> to_loops(const Paths& paths) {
  std::vector<std::vector<Point2>> out;
  out.reserve(paths.size());
  for (const Path& p : paths) {
    std::vector<Point2> loop;
    loop.reserve(p.size());
    for (const IntPoint& q : p) loop.push_back({to_mm(q.X), to_mm(q.Y)});
    out.push_back(std::move(loop));
  }
  return out;
}

double cross(Point2 a, Point2 b) { return a.x * b.y - a.y * b.x; }
Point2 minus(Point2 a, Point2 b) { return {a.x - b.x, a.y - b.y}; }

double distance_to_segment(Point2 p, Point2 a, Point2 b) {
  const Point2 d = minus(b, a), w = minus(p, a);
  const double len2 = d.x * d.x + d.y * d.y;
  const double t = len2 > 0 ? std::clamp((w.x * d.x + w.y * d.y) / len2, 0.0, 1.0) : 0.0;
  const double dx = w.x - t * d.x, dy = w.y - t * d.y;
  return std::sqrt(dx * dx + dy * dy);
}

}  // namespace

TipKeepOut::TipKeepOut(std::vector<std::vector<Point2>> loops) : loops_(std::move(loops)) {
  for (auto& l : loops_) std::reverse(l.begin(), l.end());
}

bool TipKeepOut::contains(Point2 p) const {
  bool inside = false;
  for (const auto& loop : loops_) {
    for (std::size_t i = 0, n = loop.size(); i < n; ++i) {
      const Point2 a = loop[i], b = loop[(i + 1) % n];
      if (distance_to_segment(p, a, b) <= kOnBoundary) return true;
      if ((a.y > p.y) != (b.y > p.y)) {
        const double x = a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x);
        if (x > p.x) inside = !inside;
      }
    }
  }
  return inside;
}

std::vector<double> TipKeepOut::meeting_parameters(Point2 a, Point2 b) const {
  const Point2 d = minus(b, a);
  const double len = std::hypot(d.x, d.y);
  std::vector<double> ts{0.0, 1.0};
  if (len == 0) return ts;
  constexpr double kParallel = 1e-12;
  for (const auto& loop : loops_)
    for (std::size_t i = 0, n = loop.size(); i < n; ++i) {
      const Point2 e0 = loop[i], e1 = loop[(i + 1) % n];
      const Point2 e = minus(e1, e0), w = minus(e0, a);
      const double denom = cross(d, e);
      const double elen = std::hypot(e.x, e.y);
      if (std::abs(denom) <= kParallel * len * std::max(elen, 1e-12)) {
        // Parallel: where a collinear edge overlaps, its ends cut the segment.
        if (std::abs(cross(w, d)) <= kOnBoundary * len)
          for (const Point2 q : {e0, e1}) {
            const double t = ((q.x - a.x) * d.x + (q.y - a.y) * d.y) / (len * len);
            if (t > 0 && t < 1) ts.push_back(t);
          }
        continue;
      }
      const double t = cross(w, e) / denom, u = cross(w, d) / denom;
      const double tslack = kOnBoundary / len, uslack = kOnBoundary / std::max(elen, 1e-12);
      if (t >= -tslack && t <= 1 + tslack && u >= -uslack && u <= 1 + uslack) ts.push_back(std::clamp(t, 0.0, 1.0));
    }
  std::sort(ts.begin(), ts.end());
  return ts;
}

bool TipKeepOut::segment_clear(Point2 a, Point2 b) const {
  const Point2 d = minus(b, a);
  if (std::hypot(d.x, d.y) == 0) return !contains(a) || loops_.empty();
  // Each piece between two meeting points lies wholly inside or wholly outside: test its
  // middle, which is off the boundary unless the piece runs along it (then refused).
  const std::vector<double> ts = meeting_parameters(a, b);
  for (std::size_t i = 0; i + 1 < ts.size(); ++i) {
    if (ts[i + 1] - ts[i] <= 1e-12) continue;
    const double t = (ts[i] + ts[i + 1]) / 2;
    if (contains({a.x + t * d.x, a.y + t * d.y})) return false;
  }
  return true;
}

std::vector<std::pair<Point2, Point2>> TipKeepOut::pieces_inside(Point2 a, Point2 b) const {
  std::vector<std::pair<Point2, Point2>> out;
  const Point2 d = minus(b, a);
  const auto at = [&](double t) { return Point2{a.x + t * d.x, a.y + t * d.y}; };
  if (std::hypot(d.x, d.y) == 0) {
    if (contains(a)) out.push_back({a, b});
    return out;
  }
  const std::vector<double> ts = meeting_parameters(a, b);
  for (std::size_t i = 0; i + 1 < ts.size(); ++i) {
    if (ts[i + 1] - ts[i] <= 1e-12 || !contains(at((ts[i] + ts[i + 1]) / 2))) continue;
    if (!out.empty() && std::hypot(out.back().second.x - at(ts[i]).x, out.back().second.y - at(ts[i]).y) <= 1e-12)
      out.back().second = at(ts[i + 1]);  // pieces on either side of a touching point join
    else
      out.push_back({at(ts[i]), at(ts[i + 1])});
  }
  return out;
}

Point2 TipKeepOut::nearest_on_boundary(Point2 p) const {
  Point2 best = p;
  double best_d = std::numeric_limits<double>::infinity();
  for (const auto& loop : loops_)
    for (std::size_t i = 0, n = loop.size(); i < n; ++i) {
      const Point2 a = loop[i], b = loop[(i + 1) % n];
      const Point2 e = minus(b, a), w = minus(p, a);
      const double len2 = e.x * e.x + e.y * e.y;
      const double t = len2 > 0 ? std::clamp((w.x * e.x + w.y * e.y) / len2, 0.0, 1.0) : 0.0;
      const Point2 q{a.x + t * e.x, a.y + t * e.y};
      const double dist = std::hypot(p.x - q.x, p.y - q.y);
      if (dist < best_d) best_d = dist, best = q;
    }
  return best;
}

TipKeepOut TipKeepOut::grown(double by, double chord_tolerance) const {
  Paths polys;
  polys.reserve(loops_.size());
  for (const auto& loop : loops_) {
    Path p;
    p.reserve(loop.size());
    for (auto it = loop.rbegin(); it != loop.rend(); ++it) p.push_back({to_units(it->x), to_units(it->y)});
    polys.push_back(std::move(p));
  }
  return TipKeepOut(to_loops(offset(polys, by + chord_tolerance, chord_tolerance)));
}

TipKeepOut tip_keep_out(const std::vector<Triangle>& design, double tip_z, const std::vector<ToolBand>& bands,
                        const WallFinishOptions& options) {
  Paths all;
  for (const ToolBand& b : bands) {
    const double lo = tip_z + b.from + options.floor_slack;
    const double hi = tip_z + b.to;
    if (!(hi >= lo) || !(b.radius >= 0)) continue;
    const Paths s = sections::shadow(design, lo, hi);
    if (s.empty()) continue;
    const Paths grown = offset(s, b.radius + options.chord_tolerance + options.clearance, options.chord_tolerance);
    all.insert(all.end(), grown.begin(), grown.end());
  }
  return TipKeepOut(to_loops(union_of(all, ClipperLib::pftNonZero)));
}

TipKeepOut section_shrunk(const std::vector<Triangle>& design, const std::vector<double>& heights, double inset,
                          double chord_tolerance) {
  Paths sections;
  for (const double z : heights) {
    const Paths s = sections::cross_section(design, z);
    sections.insert(sections.end(), s.begin(), s.end());
  }
  const Paths section = union_of(sections, ClipperLib::pftNonZero);
  if (section.empty()) return {};
  // Clipper gives outer loops counter-clockwise: the region on the left, as the
  // constructor takes it.
  return TipKeepOut(to_loops(offset(section, -inset, chord_tolerance)));
}

SliceMask cells_inside(const TipKeepOut& region, const SliceMask& window, const geometry::Lattice& lattice) {
  SliceMask out = window;
  const double h = lattice.voxel_size;
  std::vector<double> crossings;
  for (int y = window.y0(); y < window.y0() + window.ny(); ++y) {
    const double cy = lattice.origin.y + (y + 0.5) * h;
    crossings.clear();
    for (const auto& loop : region.loops())
      for (std::size_t i = 0, n = loop.size(); i < n; ++i) {
        const Point2 a = loop[i], b = loop[(i + 1) % n];
        if ((a.y > cy) != (b.y > cy)) crossings.push_back(a.x + (cy - a.y) / (b.y - a.y) * (b.x - a.x));
      }
    std::sort(crossings.begin(), crossings.end());
    for (std::size_t k = 0; k + 1 < crossings.size(); k += 2) {
      // Centres in [crossings[k], crossings[k + 1]], the ends included.
      const int x0 = int(std::ceil((crossings[k] - lattice.origin.x) / h - 0.5 - 1e-9)),
                x1 = int(std::floor((crossings[k + 1] - lattice.origin.x) / h - 0.5 + 1e-9));
      for (int x = std::max(x0, window.x0()); x <= std::min(x1, window.x0() + window.nx() - 1); ++x) out.set(x, y);
    }
  }
  return out;
}

std::vector<ToolBand> flat_tool_bands(const config::CuttingTool& tool_in) {
  const config::CuttingTool tool = instruments::with_defaults(tool_in);
  if (tool.type != config::ToolType::Flat) return {};
  const double r = tool.diameter / 2;
  const double shank = std::max(r, tool.shank.diameter / 2);
  const double holder = std::max(shank, tool.holder.diameter / 2);
  const double flute = tool.flute_length, shank_end = flute + tool.shank.length;
  return {{0, flute, r}, {flute, shank_end, shank}, {shank_end, kInf, holder}};
}

}  // namespace hybridctl::toolpaths
