#include "toolpaths/wall_finish.hpp"

#include <clipper.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "instruments/cutter.hpp"

// The keep-out region of a tool at one tip height, from the design's triangles, with
// Clipper (libpolyclipping) doing the unions and the offsets on integer coordinates.

namespace hybridctl::toolpaths {
namespace {

using ClipperLib::cInt;
using ClipperLib::IntPoint;
using ClipperLib::Path;
using ClipperLib::Paths;
using geometry::Triangle;
using geometry::Vec3;

// Integer units per mm: 10 nm, far below every tolerance; coordinates up to ~1e8 units
// stay in Clipper's 64-bit range with room to spare.
constexpr double kScale = 1e5;
constexpr double kInf = std::numeric_limits<double>::infinity();
// A point this close (mm) to the boundary counts as on it.
constexpr double kOnBoundary = 1e-7;

cInt to_units(double mm) { return cInt(std::llround(mm * kScale)); }
double to_mm(cInt u) { return double(u) / kScale; }

bool less3(const Vec3& a, const Vec3& b) {
  if (a.x != b.x) return a.x < b.x;
  if (a.y != b.y) return a.y < b.y;
  return a.z < b.z;
}

// Where the edge a-b meets the plane Z = h, computed from its endpoints in one order
// whichever facet asks, so that two facets sharing the edge get the same point.
Vec3 on_plane(Vec3 a, Vec3 b, double h) {
  if (less3(b, a)) std::swap(a, b);
  const double t = (h - a.z) / (b.z - a.z);
  return {a.x + t * (b.x - a.x), a.y + t * (b.y - a.y), h};
}

// Keeps the part of a convex polygon with Z >= h (above) or Z <= h.
void clip_at(std::vector<Vec3>& poly, double h, bool above) {
  if (poly.empty() || std::isinf(h)) return;
  std::vector<Vec3> out;
  out.reserve(poly.size() + 2);
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const Vec3& a = poly[i];
    const Vec3& b = poly[(i + 1) % poly.size()];
    const bool ina = above ? a.z >= h : a.z <= h;
    const bool inb = above ? b.z >= h : b.z <= h;
    if (ina) out.push_back(a);
    if (ina != inb) out.push_back(on_plane(a, b, h));
  }
  poly.swap(out);
}

// The XY projection of a polygon in integer units, repeated points dropped; empty when
// fewer than three points or no area are left (a vertical facet).
Path projected(const std::vector<Vec3>& poly) {
  Path p;
  p.reserve(poly.size());
  for (const Vec3& v : poly) {
    const IntPoint q{to_units(v.x), to_units(v.y)};
    if (p.empty() || !(p.back() == q)) p.push_back(q);
  }
  while (p.size() > 1 && p.front() == p.back()) p.pop_back();
  if (p.size() < 3 || ClipperLib::Area(p) == 0) return {};
  return p;
}

// The facet clipped to lo <= Z <= hi and projected.
Path clipped_projection(const Triangle& t, double lo, double hi) {
  std::vector<Vec3> poly{t[0], t[1], t[2]};
  clip_at(poly, lo, true);
  clip_at(poly, hi, false);
  return projected(poly);
}

Paths union_of(const Paths& polys, ClipperLib::PolyFillType fill) {
  Paths out;
  if (polys.empty()) return out;
  ClipperLib::Clipper c;
  c.AddPaths(polys, ClipperLib::ptSubject, true);
  c.Execute(ClipperLib::ctUnion, out, fill, fill);
  return out;
}

// The cross-section of the closed solid at Z = h: the points an odd number of facets lie
// over (or, the same for a closed surface, under: whichever side has fewer facets). At a
// plane that holds facets the two differ by those facets; the shadow adds them anyway.
Paths cross_section(const std::vector<Triangle>& design, double h) {
  if (std::isinf(h)) return {};
  std::size_t over = 0, under = 0;
  for (const Triangle& t : design) {
    const double lo = std::min({t[0].z, t[1].z, t[2].z}), hi = std::max({t[0].z, t[1].z, t[2].z});
    if (hi >= h) ++over;
    if (lo <= h) ++under;
  }
  const bool above = over <= under;
  Paths pieces;
  for (const Triangle& t : design) {
    const double lo = std::min({t[0].z, t[1].z, t[2].z}), hi = std::max({t[0].z, t[1].z, t[2].z});
    if (above ? hi < h : lo > h) continue;
    Path p = above ? clipped_projection(t, h, kInf) : clipped_projection(t, -kInf, h);
    if (!p.empty()) pieces.push_back(std::move(p));
  }
  return union_of(pieces, ClipperLib::pftEvenOdd);
}

// The design within lo <= Z <= hi seen from above: its cross-section at lo and every
// facet that is not vertical, clipped to the slab.
Paths shadow(const std::vector<Triangle>& design, double lo, double hi) {
  Paths pieces = cross_section(design, lo);
  for (const Triangle& t : design) {
    const double tlo = std::min({t[0].z, t[1].z, t[2].z}), thi = std::max({t[0].z, t[1].z, t[2].z});
    if (thi < lo || tlo > hi) continue;
    Path p = clipped_projection(t, lo, hi);
    if (p.empty()) continue;
    if (!ClipperLib::Orientation(p)) ClipperLib::ReversePath(p);
    pieces.push_back(std::move(p));
  }
  return union_of(pieces, ClipperLib::pftNonZero);
}

// Closed polygons grown by `delta` mm with round joins whose chords lie at most
// `chord_tolerance` mm inside their arcs. Clipper's ArcTolerance is the sag of a full step
// of its arcs, but it rounds the number of steps of a join to the nearest whole one, so
// the last chord may span up to 1.5 steps: a sag of up to 2.25 x ArcTolerance.
Paths offset(const Paths& polys, double delta, double chord_tolerance) {
  Paths out;
  if (polys.empty()) return out;
  ClipperLib::ClipperOffset o;
  o.ArcTolerance = std::max(chord_tolerance * kScale / 2.5, 1.0);
  o.AddPaths(polys, ClipperLib::jtRound, ClipperLib::etClosedPolygon);
  o.Execute(out, delta * kScale);
  return out;
}

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
    const Paths s = shadow(design, lo, hi);
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
    const Paths s = cross_section(design, z);
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
