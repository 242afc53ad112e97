#include "toolpaths/corner_reach.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <utility>

#include "instruments/cutter.hpp"
#include "toolpaths/mesh_sections.hpp"

namespace hybridctl::toolpaths {
namespace {

using geometry::Triangle;
using plan::UnreachedCorner;
using geometry::Vec3;
using sections::cInt;
using sections::IntPoint;
using sections::kScale;
using sections::Path;
using sections::Paths;
using sections::to_mm;
using sections::to_units;

constexpr double kInf = std::numeric_limits<double>::infinity();
// mm: the steps a tool's section in the prism is taken in (prism_parameter).
constexpr double kParameterStep = 0.25;
// mm: how far from the tips that would put a corner in the cutting part the free ones are
// looked for; farther counts as this far.
constexpr double kLookFor = 1.0;

struct P2 {
  double x = 0, y = 0;
};

// A tool as it stands in the plane: its radii and lengths along its axis, mm.
struct ToolShape {
  std::string name;  // "T4 (4 mm flat detail)"
  double r = 0, corner = 0, flute = 0;
  double shank_r = 0, shank_length = 0, holder_r = 0, holder_length = 0;
};

ToolShape shape_of(const config::CuttingTool& in) {
  const config::CuttingTool t = instruments::with_defaults(in);
  ToolShape s;
  s.name = "T" + std::to_string(t.number) + " (" + t.name + ")";
  s.r = t.diameter / 2;
  s.corner = t.type == config::ToolType::Ball ? s.r : t.type == config::ToolType::Bull ? t.corner_radius : 0.0;
  s.flute = t.flute_length;
  s.shank_r = t.shank.diameter / 2;
  s.shank_length = t.shank.length;
  s.holder_r = t.holder.diameter / 2;
  s.holder_length = t.holder.length;
  return s;
}

// A setup's direction as the plane sees it: along Z, or along X or Y with the tool's body
// on the `d` side of its tip.
struct Direction {
  config::Approach approach = config::Approach::PlusZ;
  bool vertical = true;
  P2 d;
};

Direction direction_of(config::Approach a) {
  switch (a) {
    case config::Approach::PlusX: return {a, false, {1, 0}};
    case config::Approach::MinusX: return {a, false, {-1, 0}};
    case config::Approach::PlusY: return {a, false, {0, 1}};
    case config::Approach::MinusY: return {a, false, {0, -1}};
    default: return {a, true, {0, 0}};
  }
}

IntPoint units(P2 p) { return {to_units(p.x), to_units(p.y)}; }

// A circle as a polygon whose vertices lie on it (inscribed: inside it) or whose edges
// touch it (circumscribed: round it), with chords within `sag` of the arc.
Path circle(P2 c, double radius, double sag, bool circumscribed) {
  const int n = std::clamp(int(std::ceil(std::numbers::pi / std::acos(std::max(-1.0, 1 - sag / std::max(radius, 1e-9))))),
                           16, 1024);
  const double rv = circumscribed ? radius / std::cos(std::numbers::pi / n) : radius;
  Path p;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * std::numbers::pi * i / n;
    p.push_back(units({c.x + rv * std::cos(a), c.y + rv * std::sin(a)}));
  }
  return p;
}

// The rectangle u in [u0, u1], v in [-half, half] of a tool whose tip is at `tip` and
// whose axis runs along d (v along d turned a quarter anticlockwise).
Path rectangle(P2 tip, P2 d, double u0, double u1, double half) {
  const P2 e{-d.y, d.x};
  const auto at = [&](double u, double v) { return units({tip.x + u * d.x + v * e.x, tip.y + u * d.y + v * e.y}); };
  return {at(u0, -half), at(u1, -half), at(u1, half), at(u0, half)};
}

// The convex pieces of the cutting part of a tool along X or Y, seen from above with its
// tip at `tip` (its widest outline: the section through its axis), cut at `length` mm.
Paths cutting_outline(const ToolShape& t, P2 tip, P2 d, double length, double sag, bool circumscribed) {
  Paths out;
  const double flute = std::min(t.flute, length);
  const P2 e{-d.y, d.x};
  const auto along = [&](double u, double v) { return P2{tip.x + u * d.x + v * e.x, tip.y + u * d.y + v * e.y}; };
  if (t.corner > 0) {
    // The rounded tip: discs of the corner radius at the corners of the flat part of the end.
    const double flat = t.r - t.corner;
    out.push_back(circle(along(t.corner, flat), t.corner, sag, circumscribed));
    if (flat > 0) {
      out.push_back(circle(along(t.corner, -flat), t.corner, sag, circumscribed));
      out.push_back(rectangle(tip, d, 0, std::max(flute, t.corner), flat));
    }
    if (flute > t.corner) out.push_back(rectangle(tip, d, t.corner, flute, t.r));
  } else {
    out.push_back(rectangle(tip, d, 0, flute, t.r));
  }
  return out;
}

Path translated(Path p, IntPoint by) {
  for (IntPoint& q : p) q.X += by.X, q.Y += by.Y;
  return p;
}

Path negated(Path p) {
  for (IntPoint& q : p) q.X = -q.X, q.Y = -q.Y;
  return p;
}

// The convex hull of `points` (Andrew's monotone chain), anticlockwise.
Path convex_hull(Path points) {
  std::sort(points.begin(), points.end(), [](const IntPoint& a, const IntPoint& b) { return a.X != b.X ? a.X < b.X : a.Y < b.Y; });
  points.erase(std::unique(points.begin(), points.end()), points.end());
  if (points.size() < 3) return points;
  const auto cross = [](const IntPoint& o, const IntPoint& a, const IntPoint& b) {
    return double(a.X - o.X) * double(b.Y - o.Y) - double(a.Y - o.Y) * double(b.X - o.X);
  };
  Path hull(2 * points.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  for (std::size_t i = points.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && cross(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  hull.resize(k - 1);
  return hull;
}

// The tip positions at which a tool whose convex pieces (around a tip at the origin) are
// `pieces` meets `region`: per piece Q, region + (-Q), as the sweep of -Q along each edge
// of the region's loops (the hull of its copies at the edge's ends), the region moved by
// -q for a point q of Q, and a copy of -Q at a point of each loop (the sum of two
// connected polygons is those three). The region's loops keep Clipper's winding (outer
// ones anticlockwise, holes clockwise), so that a hole (a bore) the sweeps leave open stays
// free under the non-zero union.
Paths blocked_by(const Paths& region, const Paths& pieces) {
  Paths all;
  for (const Path& q : pieces) {
    const Path minus_q = negated(q);
    for (const Path& loop : region) {
      for (std::size_t i = 0; i < loop.size(); ++i) {
        Path both = translated(minus_q, loop[i]);
        const Path next = translated(minus_q, loop[(i + 1) % loop.size()]);
        both.insert(both.end(), next.begin(), next.end());
        all.push_back(convex_hull(std::move(both)));
      }
      all.push_back(translated(loop, minus_q.front()));
    }
  }
  Paths out;
  ClipperLib::Clipper c;
  c.AddPaths(all, ClipperLib::ptSubject, true);
  c.Execute(ClipperLib::ctUnion, out, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
  return out;
}

double segment_distance(P2 a, P2 b, P2 c, P2 d);

// The bounding box of `paths` grown by `margin` units on every side.
ClipperLib::IntRect bounds(const Paths& paths, cInt margin) {
  ClipperLib::IntRect box{std::numeric_limits<cInt>::max(), std::numeric_limits<cInt>::max(),
                          std::numeric_limits<cInt>::min(), std::numeric_limits<cInt>::min()};
  for (const Path& p : paths)
    for (const IntPoint& q : p)
      box.left = std::min(box.left, q.X - margin), box.right = std::max(box.right, q.X + margin),
      box.top = std::min(box.top, q.Y - margin), box.bottom = std::max(box.bottom, q.Y + margin);
  return box;
}

// What of `region` lies in `box`: all that can block a tip near the corner (the rest only
// blocks tips farther than the search for free ones goes).
Paths clipped_to_box(const Paths& region, const ClipperLib::IntRect& box) {
  const Path rect{{box.left, box.top}, {box.right, box.top}, {box.right, box.bottom}, {box.left, box.bottom}};
  Paths out;
  ClipperLib::Clipper c;
  c.AddPaths(region, ClipperLib::ptSubject, true);
  c.AddPath(rect, ClipperLib::ptClip, true);
  c.Execute(ClipperLib::ctIntersection, out, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
  return out;
}

// The least distance from the region `v` (pieces) to the part of the plane outside
// `blocked`: 0 where some of v lies outside it.
double distance_to_free(const Paths& v, const Paths& blocked) {
  Paths outside;
  ClipperLib::Clipper c;
  c.AddPaths(v, ClipperLib::ptSubject, true);
  c.AddPaths(blocked, ClipperLib::ptClip, true);
  c.Execute(ClipperLib::ctDifference, outside, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
  double area = 0;
  for (const Path& p : outside) area += std::abs(ClipperLib::Area(p));
  if (area > 1.0) return 0;  // more than 1e-10 mm^2: the tool stands free there
  double best = kLookFor;
  const ClipperLib::IntRect box = bounds(v, to_units(kLookFor));
  for (const Path& b : blocked)
    for (std::size_t i = 0; i < b.size(); ++i) {
      const IntPoint e0 = b[i], e1 = b[(i + 1) % b.size()];
      if (std::max(e0.X, e1.X) < box.left || std::min(e0.X, e1.X) > box.right || std::max(e0.Y, e1.Y) < box.top ||
          std::min(e0.Y, e1.Y) > box.bottom)
        continue;
      const P2 b0{to_mm(e0.X), to_mm(e0.Y)}, b1{to_mm(e1.X), to_mm(e1.Y)};
      for (const Path& p : v)
        for (std::size_t j = 0; j < p.size(); ++j) {
          const P2 p0{to_mm(p[j].X), to_mm(p[j].Y)}, p1{to_mm(p[(j + 1) % p.size()].X), to_mm(p[(j + 1) % p.size()].Y)};
          best = std::min(best, segment_distance(b0, b1, p0, p1));
        }
    }
  return best;
}

double point_segment(P2 p, P2 a, P2 b) {
  const double dx = b.x - a.x, dy = b.y - a.y, len2 = dx * dx + dy * dy;
  const double t = len2 > 0 ? std::clamp(((p.x - a.x) * dx + (p.y - a.y) * dy) / len2, 0.0, 1.0) : 0.0;
  return std::hypot(p.x - a.x - t * dx, p.y - a.y - t * dy);
}

double segment_distance(P2 a, P2 b, P2 c, P2 d) {
  const auto cross = [](P2 o, P2 p, P2 q) { return (p.x - o.x) * (q.y - o.y) - (p.y - o.y) * (q.x - o.x); };
  const double d1 = cross(a, b, c), d2 = cross(a, b, d), d3 = cross(c, d, a), d4 = cross(c, d, b);
  if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0))) return 0;
  return std::min({point_segment(a, c, d), point_segment(b, c, d), point_segment(c, a, b), point_segment(d, a, b)});
}

// The radius of a tool's cutting part `h` mm above its tip (its profile: a flat end is
// whole at once, a ball or a bull nose rounds over its corner radius).
double profile_radius(const ToolShape& t, double h) {
  if (h >= t.corner) return t.r;
  if (h <= 0) return t.corner > 0 && t.corner < t.r ? t.r - t.corner : 0.0;
  const double k = t.corner - h;
  return t.r - t.corner + std::sqrt(std::max(0.0, t.corner * t.corner - k * k));
}

// The design round the corner is a prism from `below` under it to `above` over it (mm).
struct Prism {
  double below = 0, above = 0;
};

double nearest_along_axis(const ToolShape& tool, const Direction& dir, P2 p, const Paths& design_shrunk, double window,
                          double d, double sag);

// The nearest the cutting part of `tool` from `dir` comes to `p` while the tool stays out of
// `design_shrunk` (the cross-section in a window round p, shrunk by the allowance, the same
// over `prism`'s heights), at least; 0 where the prism is too short to tell.
//
// Along Z (from +Z; from -Z the same upside down): a tool within the reach of p has its tip
// no higher than the reach over p. With its tip a corner radius under p or lower, its
// section at p's height is a whole disc of the flutes' radius, or the shank's or the
// holder's; higher, its section at the prism's top, or a corner radius over its tip,
// whichever is lower, is a disc at least as wide as its profile that height over the
// reach. So a disc of the narrowest of those is kept out of the section.
//
// Along X or Y: a tool within the reach of p spans a height within the reach of p's, and
// its axis lies at most its radius plus the reach from p's height. At the height of the
// prism nearest its axis, d from it, the tool's section holds its spine (the segment along
// its axis from the end of its rounded tip to the holder) and the flutes', shank's and
// holder's outlines sqrt(r^2 - d^2) wide, each from the end of the rounded tip on; d is at
// most the radius plus the reach less the prism's shorter side. It reaches p with its
// cutting part's outline seen from above (its widest).
//
// What of the prism matters is one number, which the trial's answer depends on alone (with
// the section): along Z the disc's radius, along X or Y the offset d; negative where the
// prism is too short to tell.
double prism_parameter(const ToolShape& tool, const Direction& dir, Prism prism, double reach) {
  if (dir.vertical) {
    const double over = dir.approach == config::Approach::MinusZ ? prism.below : prism.above;
    if (over < reach) return -1;
    // Down to a whole step: a narrower disc blocks less, so the answer only leans towards
    // the tool, and heights a little apart share it.
    const double r_block = std::min({tool.r, tool.shank_r, tool.holder_r, profile_radius(tool, over - reach)});
    const double stepped = std::floor(r_block / kParameterStep + 1e-9) * kParameterStep;
    return stepped > 0 ? stepped : -1;
  }
  if (std::min(prism.below, prism.above) < reach) return -1;
  // Up to a whole step: farther off the axis the sections are narrower.
  const double d = std::max(0.0, tool.r + reach - std::min(prism.below, prism.above));
  const double stepped = std::ceil(d / kParameterStep - 1e-9) * kParameterStep;
  return stepped < tool.r ? stepped : -1;
}

double nearest_approach(const ToolShape& tool, const Direction& dir, P2 p, const Paths& design_shrunk, double window,
                        double parameter, double sag) {
  if (parameter < 0) return 0;
  if (dir.vertical) {
    const Paths v{circle(p, tool.r, sag, true)};
    const Paths near = clipped_to_box(design_shrunk, bounds(v, to_units(kLookFor + parameter + 1)));
    return distance_to_free(v, sections::offset(near, parameter, sag));
  }
  return nearest_along_axis(tool, dir, p, design_shrunk, window, parameter, sag);
}

// nearest_approach along X or Y, the tool's section taken d mm off its axis.
double nearest_along_axis(const ToolShape& tool, const Direction& dir, P2 p, const Paths& design_shrunk, double window,
                          double d, double sag) {
  const auto wide = [&](double radius) { return std::sqrt(std::max(0.0, radius * radius - d * d)); };
  // Nothing of the window lies farther from a tip that reaches p than this.
  const double length = std::min(window + kLookFor + 2 * tool.r, tool.flute + tool.shank_length + tool.holder_length);
  const double spine = 1.0 / kScale;  // one unit: a segment Clipper can sweep
  const double flute_end = std::min(tool.flute, length), shank_end = std::min(tool.flute + tool.shank_length, length);
  // The flutes' section: convex, as every section of a convex body; inscribed by points of
  // its edge, across the rounded tip where it is wider than the spine, and at the flutes'
  // end. The shank's and the holder's sections are rectangles.
  constexpr int kTipSteps = 12;
  const P2 e{-dir.d.y, dir.d.x};
  const auto at = [&](double u, double v) { return units({u * dir.d.x + v * e.x, u * dir.d.y + v * e.y}); };
  Path flutes{at(flute_end, -std::max(spine, wide(tool.r))), at(flute_end, std::max(spine, wide(tool.r)))};
  for (int k = 0; k <= kTipSteps && tool.corner > 0; ++k) {
    const double u = std::min(flute_end, tool.corner * k / kTipSteps), w = wide(profile_radius(tool, u));
    if (w > spine) flutes.push_back(at(u, -w)), flutes.push_back(at(u, w));
  }
  flutes.push_back(at(tool.corner, -spine));
  flutes.push_back(at(tool.corner, spine));
  if (tool.corner == 0) flutes.push_back(at(0, -wide(tool.r))), flutes.push_back(at(0, wide(tool.r)));
  flutes = convex_hull(std::move(flutes));
  Paths pieces{flutes};
  const auto rect_from_axis = [&](double u0, double u1, double half) {
    return Path{at(u0, -half), at(u1, -half), at(u1, half), at(u0, half)};
  };
  if (shank_end > flute_end) pieces.push_back(rect_from_axis(flute_end, shank_end, std::max(spine, wide(tool.shank_r))));
  if (length > shank_end) pieces.push_back(rect_from_axis(shank_end, length, std::max(spine, wide(tool.holder_r))));
  // The tips whose cutting part holds p: p - Q for each of its pieces.
  Paths v;
  for (const Path& q : cutting_outline(tool, {0, 0}, dir.d, length, sag, true)) {
    Path moved = translated(negated(q), units(p));
    if (!ClipperLib::Orientation(moved)) ClipperLib::ReversePath(moved);
    v.push_back(std::move(moved));
  }
  // The section that can meet the pieces of a tip near those: near + Q.
  ClipperLib::IntRect box = bounds(v, to_units(kLookFor + 1));
  const ClipperLib::IntRect q = bounds(pieces, 0);
  box.left += q.left, box.right += q.right, box.top += q.top, box.bottom += q.bottom;
  const Paths blocked = blocked_by(clipped_to_box(design_shrunk, box), pieces);
  return distance_to_free(v, blocked);
}

// A facet that is not vertical, as the windows need it: its heights and its outline from above.
struct SlopedFacet {
  double lo = 0, hi = 0;
  P2 a, b, c;
};

double point_triangle_2d(P2 p, const SlopedFacet& f) {
  const auto side = [](P2 o, P2 q, P2 r) { return (q.x - o.x) * (r.y - o.y) - (q.y - o.y) * (r.x - o.x); };
  const double s1 = side(f.a, f.b, p), s2 = side(f.b, f.c, p), s3 = side(f.c, f.a, p);
  if ((s1 >= 0 && s2 >= 0 && s3 >= 0) || (s1 <= 0 && s2 <= 0 && s3 <= 0)) return 0;
  return std::min({point_segment(p, f.a, f.b), point_segment(p, f.b, f.c), point_segment(p, f.c, f.a)});
}

// An inside corner of one cross-section: where it is and the air's angle there.
struct SectionCorner {
  P2 at;
  IntPoint key;
  double air_angle = 0;
};

// The vertices of the section's loops where the air's angle is at most `max_air_angle`
// degrees (the solid lies left of Clipper's loops, holes included), the angle taken
// between the loop's points a little way either side, so that the few units Clipper's
// rounding leaves between two vertices of one corner do not split it.
std::vector<SectionCorner> inside_corners(const Paths& section, double max_air_angle) {
  const double away = to_units(0.01);
  std::vector<SectionCorner> out;
  for (const Path& loop : section) {
    const std::size_t n = loop.size();
    const auto far_from = [&](std::size_t i, std::size_t step) {
      std::size_t j = i;
      for (std::size_t k = 1; k < n; ++k) {
        j = (j + step) % n;
        if (std::hypot(double(loop[j].X - loop[i].X), double(loop[j].Y - loop[i].Y)) >= away) break;
      }
      return loop[j];
    };
    for (std::size_t i = 0; i < n; ++i) {
      const IntPoint a = far_from(i, n - 1), b = loop[i], c = far_from(i, 1);
      // One vertex of a corner whose others lie within the look-around: the corner's
      // first is named.
      const IntPoint before = loop[(i + n - 1) % n];
      if (std::hypot(double(b.X - before.X), double(b.Y - before.Y)) < away) continue;
      const double e1x = double(b.X - a.X), e1y = double(b.Y - a.Y), e2x = double(c.X - b.X), e2y = double(c.Y - b.Y);
      const double turn = std::atan2(e1x * e2y - e1y * e2x, e1x * e2x + e1y * e2y);
      if (turn >= 0) continue;  // a left turn: the solid's own corner, convex
      const double air = 180 + turn * 180 / std::numbers::pi;
      if (air <= max_air_angle && air > 1) out.push_back({{to_mm(b.X), to_mm(b.Y)}, b, air});
    }
  }
  return out;
}

// One corner tried at one height.
struct Trial {
  double z = 0;
  bool unreached = false;
  double nearest = 0;
  std::string by;
  double air_angle = 0;
};

// Every tool from every direction.
struct Approach {
  const ToolShape* tool = nullptr;
  Direction dir;
};

// How far under and over `at`, at height z, the design within `window` of it stays a
// prism: up to the nearest facet that is not vertical there (none may span z itself).
Prism prism_round(P2 at, double z, double window, const std::vector<SlopedFacet>& sloped) {
  Prism p{kInf, kInf};
  for (const SlopedFacet& f : sloped) {
    if (f.hi < z - p.below || f.lo > z + p.above) continue;
    if (point_triangle_2d(at, f) >= window) continue;
    if (f.lo > z) p.above = std::min(p.above, f.lo - z);
    else if (f.hi < z) p.below = std::min(p.below, z - f.hi);
    else return {0, 0};
  }
  return p;
}

Paths clipped_to_disc(const Paths& section, P2 at, double radius, double sag) {
  Paths out;
  ClipperLib::Clipper clip;
  clip.AddPaths(section, ClipperLib::ptSubject, true);
  clip.AddPath(circle(at, radius, sag, false), ClipperLib::ptClip, true);
  clip.Execute(ClipperLib::ctIntersection, out, ClipperLib::pftEvenOdd, ClipperLib::pftNonZero);
  return out;
}

// A corner seen in one cross-section.
struct Sighting {
  double z = 0;
  Prism prism;
  double air_angle = 0;
  P2 at;
  std::size_t around = 0;  // which of the corner's windowed sections
};

// One approach's answers over a run of heights that see the same section round a corner:
// per prism parameter, the nearest approach (a bound: see settle_approach).
using Answers = std::map<double, double>;

// What approach `a` makes of the corner at each of `parameters` (prism_parameter's, one per
// height). Blocking only grows with the parameter along Z (a wider disc) and shrinks with it
// along X or Y (a section farther off the axis), so the parameters, strictest first, are
// unreached up to a point and reached after it: a binary search finds the point, and a
// parameter unreached stands with the nearest found at the most lenient one unreached
// (no nearer than its own). Parameters the prism cannot judge (negative) are reached.
Answers settle_approach(const Approach& a, P2 at, const Paths& shrunk, const std::vector<double>& parameters,
                        const CornerReachOptions& o) {
  std::vector<double> order;
  for (const double p : parameters)
    if (p >= 0) order.push_back(p);
  std::sort(order.begin(), order.end());
  order.erase(std::unique(order.begin(), order.end()), order.end());
  // Strictest first: along Z the widest disc, along X or Y the section nearest the axis.
  if (a.dir.vertical) std::reverse(order.begin(), order.end());
  Answers out{{-1.0, 0.0}};
  std::map<double, double> seen;
  const auto nearest = [&](std::size_t k) {
    const auto [it, fresh] = seen.try_emplace(order[k], 0.0);
    if (fresh) it->second = nearest_approach(*a.tool, a.dir, at, shrunk, o.max_window, order[k], o.chord_tolerance);
    return it->second;
  };
  // Unreached for order[0 .. last_unreached], reached after.
  std::ptrdiff_t lo = -1, hi = std::ptrdiff_t(order.size());
  while (hi - lo > 1) {
    // The strictest first (reached there, reached everywhere), then the most lenient
    // (unreached there, unreached everywhere), then halves.
    const std::ptrdiff_t mid = lo == -1 ? 0 : hi == std::ptrdiff_t(order.size()) ? hi - 1 : (lo + hi) / 2;
    if (nearest(std::size_t(mid)) > o.reach) lo = mid;
    else hi = mid;
  }
  for (std::size_t k = 0; k < order.size(); ++k)
    out[order[k]] = std::ptrdiff_t(k) <= lo ? nearest(std::size_t(lo)) : seen.count(order[k]) ? seen[order[k]] : 0.0;
  return out;
}

// The trials of a corner over a run of heights with the same section round it.
std::vector<Trial> try_run(const std::vector<Sighting>& run, const Paths& around, const std::vector<Approach>& approaches,
                           const CornerReachOptions& o) {
  std::vector<Trial> trials;
  for (const Sighting& s : run) trials.push_back({s.z, true, kInf, "", s.air_angle});
  const Paths shrunk = sections::offset(around, -o.allowance, o.chord_tolerance);
  for (const Approach& a : approaches) {
    std::vector<double> parameters;
    for (const Sighting& s : run) parameters.push_back(prism_parameter(*a.tool, a.dir, s.prism, o.reach));
    const Answers answers = settle_approach(a, run.front().at, shrunk, parameters, o);
    bool any_unreached = false;
    for (std::size_t h = 0; h < run.size(); ++h) {
      const double near_mm = answers.at(parameters[h] < 0 ? -1.0 : parameters[h]);
      if (near_mm < trials[h].nearest)
        trials[h].nearest = near_mm, trials[h].by = a.tool->name + " from " + std::string(config::to_string(a.dir.approach));
      any_unreached = any_unreached || trials[h].nearest > o.reach;
    }
    if (!any_unreached) break;  // reached at every height
  }
  for (Trial& t : trials) t.unreached = t.nearest > o.reach;
  return trials;
}

// The runs of heights one step apart that `trials` found unreached at `at`, each at least
// options.min_stretch long, appended to `out`.
void named_stretches(P2 at, const std::vector<Trial>& trials, const CornerReachOptions& o,
                     std::vector<UnreachedCorner>& out) {
  for (std::size_t i = 0; i < trials.size();) {
    if (!trials[i].unreached) {
      ++i;
      continue;
    }
    std::size_t j = i;
    double nearest = trials[i].nearest;
    std::string by = trials[i].by;
    while (j + 1 < trials.size() && trials[j + 1].unreached && trials[j + 1].z - trials[j].z < o.step * 1.5) {
      ++j;
      if (trials[j].nearest < nearest) nearest = trials[j].nearest, by = trials[j].by;
    }
    if (trials[j].z - trials[i].z >= o.min_stretch - 1e-9)
      out.push_back({{at.x, at.y, trials[i].z}, {at.x, at.y, trials[j].z}, trials[i].air_angle, nearest, by});
    i = j + 1;
  }
}

}  // namespace

std::vector<UnreachedCorner> corners_no_cutter_reaches(const std::vector<Triangle>& design, const config::Machine& machine,
                                                       const CornerReachOptions& o) {
  std::vector<ToolShape> tools;
  for (const config::CuttingTool& t : machine.tools) tools.push_back(shape_of(t));
  // The narrowest tools first: they come nearest, and one that reaches ends the trial.
  std::sort(tools.begin(), tools.end(), [](const ToolShape& a, const ToolShape& b) { return a.r < b.r; });
  std::vector<Approach> approaches;
  for (const ToolShape& t : tools)
    for (const config::Setup& s : machine.setups) {
      const Direction d = direction_of(s.approach);
      const bool twice = std::any_of(approaches.begin(), approaches.end(),
                                     [&](const Approach& e) { return e.tool == &t && e.dir.approach == d.approach; });
      if (!twice) approaches.push_back({&t, d});
    }
  if (design.empty() || approaches.empty()) return {};

  std::vector<SlopedFacet> sloped;
  double zmin = kInf, zmax = -kInf;
  for (const Triangle& t : design) {
    const double lo = std::min({t[0].z, t[1].z, t[2].z}), hi = std::max({t[0].z, t[1].z, t[2].z});
    zmin = std::min(zmin, lo), zmax = std::max(zmax, hi);
    const double nz = (t[1].x - t[0].x) * (t[2].y - t[0].y) - (t[1].y - t[0].y) * (t[2].x - t[0].x);
    if (std::abs(nz) > 1e-12) sloped.push_back({lo, hi, {t[0].x, t[0].y}, {t[1].x, t[1].y}, {t[2].x, t[2].y}});
  }
  using Key = std::pair<ClipperLib::cInt, ClipperLib::cInt>;
  // Where each corner is seen, and the sections round it (a prism's corner has the same
  // section at every height), then its trials run by run of heights with one section.
  std::map<Key, std::vector<Sighting>> sightings;
  std::map<Key, std::vector<Paths>> arounds;
  for (double z = zmin + o.step / 2; z < zmax; z += o.step) {
    // The facets' union leaves one region in pieces along the facets' edges (a pocket's
    // floor in its triangles): joined again, and what rounding left a few units apart
    // cleaned away.
    Paths section = sections::union_of(sections::cross_section(design, z), ClipperLib::pftNonZero);
    ClipperLib::CleanPolygons(section, 10);
    for (const SectionCorner& c : inside_corners(section, o.max_air_angle)) {
      const Key key{c.key.X, c.key.Y};
      Paths around = clipped_to_disc(section, c.at, o.max_window, o.chord_tolerance);
      std::vector<Paths>& seen = arounds[key];
      if (seen.empty() || seen.back() != around) seen.push_back(std::move(around));
      sightings[key].push_back({z, prism_round(c.at, z, o.max_window, sloped), c.air_angle, c.at, seen.size() - 1});
    }
  }
  std::vector<UnreachedCorner> out;
  for (const auto& [key, list] : sightings) {
    // Enough named: a part with many such corners (a gear's roots) is not tried whole.
    if (out.size() >= o.max_corners) break;
    std::vector<Trial> trials;
    for (std::size_t i = 0; i < list.size();) {
      std::size_t j = i;
      while (j < list.size() && list[j].around == list[i].around) ++j;
      const std::vector<Sighting> run(list.begin() + std::ptrdiff_t(i), list.begin() + std::ptrdiff_t(j));
      for (Trial& t : try_run(run, arounds[key][list[i].around], approaches, o)) trials.push_back(std::move(t));
      i = j;
    }
    named_stretches(P2{to_mm(key.first), to_mm(key.second)}, trials, o, out);
  }
  std::sort(out.begin(), out.end(), [](const UnreachedCorner& a, const UnreachedCorner& b) {
    if (a.from.z != b.from.z) return a.from.z < b.from.z;
    if (a.from.x != b.from.x) return a.from.x < b.from.x;
    return a.from.y < b.from.y;
  });
  return out;
}

}  // namespace hybridctl::toolpaths
