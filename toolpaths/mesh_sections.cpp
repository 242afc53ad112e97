#include "toolpaths/mesh_sections.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

// The design's cross-sections and shadows as Clipper polygons, and their offsets: what
// wall finishing and the corner reach proof both cut out of the STL's triangles.

namespace hybridctl::toolpaths::sections {
namespace {

using geometry::Triangle;
using geometry::Vec3;

constexpr double kInf = std::numeric_limits<double>::infinity();

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

}  // namespace

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

}  // namespace hybridctl::toolpaths::sections
