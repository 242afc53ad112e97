#include "verification/line_sweep.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <Eigen/Core>

namespace hybridctl::verification {
namespace {

using V3 = Eigen::Vector3d;
using Kind = sim::ConvexPiece::Kind;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kTiny = 1e-12;

V3 v3(const geometry::Vec3& v) { return {v.x, v.y, v.z}; }

Span all() { return {-kInf, kInf}; }
Span none() { return {}; }
Span meet(Span a, Span b) { return {std::max(a.lo, b.lo), std::min(a.hi, b.hi)}; }
// The smallest interval holding both (the pieces of one convex volume overlap).
Span hull(Span a, Span b) {
  if (a.empty()) return b;
  if (b.empty()) return a;
  return {std::min(a.lo, b.lo), std::max(a.hi, b.hi)};
}

// t with a t^2 + b t + c <= 0, for a >= 0.
Span quadratic_at_most_zero(double a, double b, double c) {
  if (a <= kTiny) {
    if (std::abs(b) <= kTiny) return c <= 0 ? all() : none();
    return b > 0 ? Span{-kInf, -c / b} : Span{-c / b, kInf};
  }
  const double disc = b * b - 4 * a * c;
  if (disc < 0) return none();
  const double root = std::sqrt(disc);
  // The stable pair of roots.
  const double q = -0.5 * (b + (b >= 0 ? root : -root));
  double r1 = q / a, r2 = std::abs(q) > kTiny ? c / q : r1;
  if (r1 > r2) std::swap(r1, r2);
  return {r1, r2};
}

// t with lo <= p + t d <= hi (one coordinate).
Span slab(double p, double d, double lo, double hi) {
  if (std::abs(d) <= kTiny) return p >= lo && p <= hi ? all() : none();
  double a = (lo - p) / d, b = (hi - p) / d;
  if (a > b) std::swap(a, b);
  return {a, b};
}

Span ball(const V3& p, const V3& d, const V3& c, double r) {
  const V3 w = p - c;
  return quadratic_at_most_zero(d.dot(d), 2 * d.dot(w), w.dot(w) - r * r);
}

// The capsule of radius r around segment e0-e1 (a ball when they coincide).
Span capsule(const V3& p, const V3& d, const V3& e0, const V3& e1, double r) {
  Span s = hull(ball(p, d, e0, r), ball(p, d, e1, r));
  const V3 axis = e1 - e0;
  const double length = axis.norm();
  if (length <= kTiny) return s;
  const V3 u = axis / length;
  const V3 w = p - e0;
  const V3 wp = w - w.dot(u) * u, dp = d - d.dot(u) * u;
  const Span tube = quadratic_at_most_zero(dp.dot(dp), 2 * dp.dot(wp), wp.dot(wp) - r * r);
  return hull(s, meet(tube, slab(w.dot(u), d.dot(u), 0, length)));
}

// The length of (x, y): std::hypot guards against overflow, which lengths in
// mm never come near, at several times the cost, in the innermost loops of a sweep.
double norm(double x, double y) { return std::sqrt(x * x + y * y); }

// t with (p + t d - c) in the disc of radius r about c, in XY.
Span disc_xy(double px, double py, double dx, double dy, double cx, double cy, double r) {
  const double wx = px - cx, wy = py - cy;
  return quadratic_at_most_zero(dx * dx + dy * dy, 2 * (dx * wx + dy * wy), wx * wx + wy * wy - r * r);
}

// A capsule in XY (z ignored) against the line's XY projection, in plain 2D: the two end
// discs and the rectangle between them (two slabs across and along the segment). This is
// the sweep of every level or plunging cylinder, the most frequent question by far.
Span capsule_xy(const V3& p, const V3& d, const V3& a, const V3& b, double r) {
  const double dx = d.x(), dy = d.y();
  if (dx * dx + dy * dy <= kTiny) {
    // The line stands still in XY: inside everywhere or nowhere.
    const double ux = b.x() - a.x(), uy = b.y() - a.y(), wx = p.x() - a.x(), wy = p.y() - a.y();
    const double uu = ux * ux + uy * uy;
    const double s = uu > kTiny ? std::clamp((wx * ux + wy * uy) / uu, 0.0, 1.0) : 0.0;
    const double ex = wx - s * ux, ey = wy - s * uy;
    return ex * ex + ey * ey <= r * r ? all() : none();
  }
  Span s = disc_xy(p.x(), p.y(), dx, dy, a.x(), a.y(), r);
  const double ux = b.x() - a.x(), uy = b.y() - a.y();
  const double length = norm(ux, uy);
  if (length <= kTiny) return s;
  s = hull(s, disc_xy(p.x(), p.y(), dx, dy, b.x(), b.y(), r));
  const double cx = ux / length, cy = uy / length;  // along the segment; (-cy, cx) across it
  const double wx = p.x() - a.x(), wy = p.y() - a.y();
  const Span rectangle = meet(slab(wx * cx + wy * cy, dx * cx + dy * cy, 0, length),
                              slab(-wx * cy + wy * cx, -dx * cy + dy * cx, -r, r));
  return hull(s, rectangle);
}

// Distance in XY from q to the segment a-b.
double distance_xy(const V3& q, const V3& a, const V3& b) {
  const double ux = b.x() - a.x(), uy = b.y() - a.y();
  const double wx = q.x() - a.x(), wy = q.y() - a.y();
  const double uu = ux * ux + uy * uy;
  const double s = uu > kTiny ? std::clamp((wx * ux + wy * uy) / uu, 0.0, 1.0) : 0.0;
  return norm(wx - s * ux, wy - s * uy);
}

// The piece's convex gauge at v (relative to its programmed point): <= 0 inside.
double gauge(const sim::ConvexPiece& piece, const V3& v) {
  const double slab_term = std::max(piece.from - v.z(), v.z() - piece.to);
  const double radial = norm(v.x(), v.y());
  double shape = 0;
  switch (piece.kind) {
    case Kind::Cylinder: shape = radial - piece.radius; break;
    case Kind::Sphere: shape = norm(radial, v.z() - piece.centre) - piece.radius; break;
    case Kind::Ellipsoid:
      shape = norm(radial, (v.z() - piece.centre) * piece.radius / piece.half_height) - piece.radius;
      break;
    case Kind::Torus: shape = norm(std::max(0.0, radial - piece.ring), v.z() - piece.centre) - piece.radius; break;
  }
  return std::max(shape, slab_term);
}

// Minimum of a convex function on [a, b] by golden-section search: where it is.
template <class F>
double argmin_convex(F f, double a, double b, int iterations) {
  constexpr double r = 0.6180339887498949;
  double x1 = b - r * (b - a), x2 = a + r * (b - a);
  double f1 = f(x1), f2 = f(x2);
  for (int i = 0; i < iterations && b - a > 1e-13; ++i) {
    if (f1 <= f2) {
      b = x2, x2 = x1, f2 = f1;
      x1 = b - r * (b - a), f1 = f(x1);
    } else {
      a = x1, x1 = x2, f1 = f2;
      x2 = a + r * (b - a), f2 = f(x2);
    }
  }
  return f1 <= f2 ? x1 : x2;
}

// {t in [t0, t1] : g(t) <= 0} for a convex g: one interval. The line meets a convex
// volume in one interval, so a point found inside (an end, or a point of a coarse scan)
// is where both edges are searched from; only when none is, the minimum is searched for,
// bracketed by the scan (which also keeps a g that is only piecewise convex from
// misleading the search).
template <class G>
Span sublevel(G g, double t0, double t1) {
  const double g0 = g(t0), g1 = g(t1);
  auto edge = [&](double outside, double g_outside, double inside) {
    if (g_outside <= 0) return outside;
    for (int i = 0; i < 34 && std::abs(inside - outside) > 1e-9; ++i) {
      const double mid = 0.5 * (inside + outside);
      (g(mid) <= 0 ? inside : outside) = mid;
    }
    return inside;
  };
  if (g0 <= 0 || g1 <= 0) {
    const double inside = g0 <= 0 ? t0 : t1;
    return {edge(t0, g0, inside), edge(t1, g1, inside)};
  }
  constexpr int kScan = 16;
  int best = 0;
  double lowest = g0;
  for (int k = 1; k < kScan; ++k) {
    const double tk = t0 + (t1 - t0) * k / kScan;
    const double v = g(tk);
    if (v <= 0) return {edge(t0, g0, tk), edge(t1, g1, tk)};
    if (v < lowest) lowest = v, best = k;
  }
  if (g1 < lowest) best = kScan;
  const double step = (t1 - t0) / kScan;
  const double tm = argmin_convex(g, std::max(t0, t0 + (best - 1) * step), std::min(t1, t0 + (best + 1) * step), 32);
  if (g(tm) > 0) return none();
  return {edge(t0, g0, tm), edge(t1, g1, tm)};
}

// Whether the stretch [t0, t1] of the line surely misses the sweep: it lies above or below
// every height the piece reaches, or its middle is farther in XY from the segment than the
// piece's reach and the stretch's own half length together. Most stretches a sweep asks
// about are settled by this, without the exact geometry below.
bool surely_misses(const sim::ConvexPiece& piece, const V3& p, const V3& d, double t0, double t1, const V3& a,
                   const V3& b) {
  const double za = p.z() + t0 * d.z(), zb = p.z() + t1 * d.z();
  if (std::max(za, zb) < std::min(a.z(), b.z()) + piece.from || std::min(za, zb) > std::max(a.z(), b.z()) + piece.to)
    return true;
  const V3 m = p + 0.5 * (t0 + t1) * d;
  const double half = 0.5 * (t1 - t0) * norm(d.x(), d.y());
  return distance_xy(m, a, b) > piece.reach() + half;
}

// A cylinder moved along a ramp, in closed form. With t the line's parameter and s the
// segment's (the piece at a + s m), the pairs (t, s) that put the line's point in the
// piece are a convex region of the plane: half-planes (s in [0, 1], t in [t0, t1], the
// height within the piece's slab) and the disc in XY, a quadratic Q(t, s) <= 0. Its
// least and greatest t lie where two half-planes' lines cross, where a line meets Q = 0,
// or where Q = 0 runs square to t (dQ/ds = 0); every such point that lies in the region
// is a candidate. When the line and the ramp run parallel in XY (or either stands still
// there) Q is a strip between two lines, which joins the half-planes.
Span cylinder_on_ramp(const sim::ConvexPiece& piece, const V3& p, const V3& d, const V3& a, const V3& m, double t0,
                      double t1) {
  struct Line {
    double at, as, c;  // at t + as s <= c
  };
  std::array<Line, 8> lines;
  std::size_t n = 0;
  const auto add = [&](double at, double as, double c) {
    if (std::isfinite(c)) lines[n++] = {at, as, c};
  };
  add(0, -1, 0), add(0, 1, 1), add(-1, 0, -t0), add(1, 0, t1);
  // The height: from <= p.z - a.z + t d.z - s m.z <= to.
  const double wz = p.z() - a.z();
  add(-d.z(), m.z(), wz - piece.from);
  add(d.z(), -m.z(), piece.to - wz);
  // XY: |w + t u - s v| <= r.
  const double wx = p.x() - a.x(), wy = p.y() - a.y(), ux = d.x(), uy = d.y(), vx = m.x(), vy = m.y();
  const double uu = ux * ux + uy * uy, vv = vx * vx + vy * vy, uv = ux * vx + uy * vy, ww = wx * wx + wy * wy;
  const double cross = ux * vy - uy * vx, r2 = piece.radius * piece.radius;
  // Q(t, s) = qtt t^2 + 2 qts t s + qss s^2 + 2 qt t + 2 qs s + q0.
  const double qtt = uu, qts = -uv, qss = vv, qt = wx * ux + wy * uy, qs = -(wx * vx + wy * vy), q0 = ww - r2;
  const bool strip = cross * cross <= 1e-12 * std::max(1e-300, uu * vv) || uu <= kTiny || vv <= kTiny;
  if (strip) {
    if (uu <= kTiny && vv <= kTiny) {
      if (q0 > 0) return none();
    } else {
      const double len = std::sqrt(vv > kTiny ? vv : uu);
      const double ex = (vv > kTiny ? vx : ux) / len, ey = (vv > kTiny ? vy : uy) / len;
      const double along = wx * ex + wy * ey, across2 = ww - along * along;
      if (across2 > r2) return none();
      const double half = std::sqrt(r2 - across2), ua = ux * ex + uy * ey, va = vx * ex + vy * ey;
      add(ua, -va, half - along);
      add(-ua, va, half + along);
    }
  }
  const auto q_of = [&](double t, double u) {
    return qtt * t * t + 2 * qts * t * u + qss * u * u + 2 * qt * t + 2 * qs * u + q0;
  };
  const double eps = 1e-9;
  const auto feasible = [&](double t, double u) {
    for (std::size_t k = 0; k < n; ++k)
      if (lines[k].at * t + lines[k].as * u > lines[k].c + eps * (1 + std::abs(lines[k].c))) return false;
    return strip || q_of(t, u) <= eps * (1 + r2);
  };
  Span out;
  const auto consider = [&](double t, double u) {
    if (!std::isfinite(t) || !std::isfinite(u) || !feasible(t, u)) return;
    out = out.empty() ? Span{t, t} : Span{std::min(out.lo, t), std::max(out.hi, t)};
  };
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j) {
      const Line& l = lines[i];
      const Line& k = lines[j];
      const double det = l.at * k.as - l.as * k.at;
      if (std::abs(det) <= kTiny) continue;
      consider((l.c * k.as - l.as * k.c) / det, (l.at * k.c - l.c * k.at) / det);
    }
  if (!strip) {
    // Q along a line u = alpha + beta t (or t = alpha + beta u): a quadratic's roots.
    const auto roots = [](double A, double B, double C, double out2[2]) {
      if (std::abs(A) <= kTiny) {
        if (std::abs(B) <= kTiny) return 0;
        out2[0] = -C / B;
        return 1;
      }
      const double disc = B * B - 4 * A * C;
      if (disc < 0) return 0;
      const double root = std::sqrt(disc), q = -0.5 * (B + (B >= 0 ? root : -root));
      out2[0] = q / A;
      out2[1] = std::abs(q) > kTiny ? C / q : out2[0];
      return 2;
    };
    const auto on_u_of_t = [&](double alpha, double beta) {  // u = alpha + beta t
      double r[2];
      const int k = roots(qtt + 2 * qts * beta + qss * beta * beta,
                          2 * (qts * alpha + qss * alpha * beta + qt + qs * beta),
                          qss * alpha * alpha + 2 * qs * alpha + q0, r);
      for (int i = 0; i < k; ++i) consider(r[i], alpha + beta * r[i]);
    };
    const auto on_t_of_u = [&](double alpha, double beta) {  // t = alpha + beta u
      double r[2];
      const int k = roots(qss + 2 * qts * beta + qtt * beta * beta,
                          2 * (qts * alpha + qtt * alpha * beta + qs + qt * beta),
                          qtt * alpha * alpha + 2 * qt * alpha + q0, r);
      for (int i = 0; i < k; ++i) consider(alpha + beta * r[i], r[i]);
    };
    for (std::size_t i = 0; i < n; ++i) {
      const Line& l = lines[i];
      if (std::abs(l.as) >= std::abs(l.at)) on_u_of_t(l.c / l.as, -l.at / l.as);
      else on_t_of_u(l.c / l.at, -l.as / l.at);
    }
    on_u_of_t(-qs / qss, -qts / qss);  // where Q = 0 runs square to t
  }
  return out;
}

bool whole_in_slab(const sim::ConvexPiece& piece, double half_height) {
  return piece.from <= piece.centre - half_height + 1e-12 && piece.to >= piece.centre + half_height - 1e-12;
}

}  // namespace

Span line_in_sweep(const sim::ConvexPiece& piece, const sim::Segment& segment, const geometry::Vec3& p_in,
                   const geometry::Vec3& d_in, double t0, double t1) {
  const V3 p = v3(p_in), d = v3(d_in), a = v3(segment.from), b = v3(segment.to);
  const V3 move = b - a;
  // Within a nanometre of level or of vertical is taken as such (frames and origins leave
  // rounding in the last digits).
  const bool level = std::abs(move.z()) <= 1e-9;
  const bool vertical = std::abs(move.x()) <= 1e-9 && std::abs(move.y()) <= 1e-9;
  if (!(t0 <= t1) || surely_misses(piece, p, d, t0, t1, a, b)) return none();
  Span range{t0, t1};
  switch (piece.kind) {
    case Kind::Cylinder:
      // The slab first: most lines a sweep is asked about pass above or below it.
      if (level) {
        range = meet(range, slab(p.z(), d.z(), a.z() + piece.from, a.z() + piece.to));
        return range.empty() ? none() : meet(range, capsule_xy(p, d, a, b, piece.radius));
      }
      if (vertical) {
        range = meet(range, slab(p.z(), d.z(), std::min(a.z(), b.z()) + piece.from, std::max(a.z(), b.z()) + piece.to));
        return range.empty() ? none() : meet(range, capsule_xy(p, d, a, a, piece.radius));
      }
      break;
    case Kind::Sphere:
      if (whole_in_slab(piece, piece.radius)) {
        const V3 up(0, 0, piece.centre);
        return meet(range, capsule(p, d, a + up, b + up, piece.radius));
      }
      break;
    case Kind::Ellipsoid:
      if (whole_in_slab(piece, piece.half_height)) {
        // Scaling Z by radius / half_height turns the ellipsoid into a ball.
        const double k = piece.radius / piece.half_height;
        const V3 scale(1, 1, k), up(0, 0, piece.centre);
        return meet(range, capsule(p.cwiseProduct(scale), d.cwiseProduct(scale), (a + up).cwiseProduct(scale),
                                   (b + up).cwiseProduct(scale), piece.radius));
      }
      break;
    case Kind::Torus:
      if (level && whole_in_slab(piece, piece.radius)) {
        const V3 a2(a.x(), a.y(), 0), b2(b.x(), b.y(), 0);
        const double zc = a.z() + piece.centre;
        // Within the prism around it (its slab, the capsule of its reach) first.
        range = meet(range, meet(slab(p.z(), d.z(), zc - piece.radius, zc + piece.radius),
                                 capsule_xy(p, d, a, b, piece.reach())));
        if (range.empty()) return none();
        t0 = range.lo, t1 = range.hi;
        return sublevel(
            [&](double t) {
              const V3 q = p + t * d;
              return norm(std::max(0.0, distance_xy(q, a2, b2) - piece.ring), q.z() - zc) - piece.radius;
            },
            t0, t1);
      }
      if (vertical && whole_in_slab(piece, piece.radius)) {
        const double z0 = std::min(a.z(), b.z()) + piece.centre, z1 = std::max(a.z(), b.z()) + piece.centre;
        range = meet(range, meet(slab(p.z(), d.z(), z0 - piece.radius, z1 + piece.radius),
                                 capsule_xy(p, d, a, a, piece.reach())));
        if (range.empty()) return none();
        t0 = range.lo, t1 = range.hi;
        return sublevel(
            [&](double t) {
              const V3 q = p + t * d;
              const double dz = q.z() < z0 ? z0 - q.z() : q.z() > z1 ? q.z() - z1 : 0.0;
              return norm(std::max(0.0, norm(q.x() - a.x(), q.y() - a.y()) - piece.ring), dz) - piece.radius;
            },
            t0, t1);
      }
      break;
  }
  if (piece.kind == Kind::Cylinder) return cylinder_on_ramp(piece, p, d, a, move, t0, t1);
  if (piece.kind == Kind::Torus) {
    // On a ramp: first the cylinder of its reach over its height, which holds it (closed
    // form above), so that a line that misses costs no search and one that meets it is
    // searched over that span only.
    sim::ConvexPiece hull;
    hull.kind = Kind::Cylinder;
    hull.radius = piece.reach();
    hull.from = piece.centre - piece.radius;
    hull.to = piece.centre + piece.radius;
    range = meet(range, line_in_sweep(hull, segment, p_in, d_in, t0, t1));
    if (range.empty()) return none();
    t0 = range.lo, t1 = range.hi;
  }
  // Any other case: the general convex sublevel set, minimising over the segment inside,
  // searched only where the ball around the piece's slab meets the line.
  if (std::isfinite(piece.to)) {
    const double half = 0.5 * (piece.to - piece.from);
    const V3 mid(0, 0, piece.from + half);
    range = meet(range, capsule(p, d, a + mid, b + mid, std::hypot(piece.reach(), half)));
    if (range.empty()) return none();
    t0 = range.lo, t1 = range.hi;
  }
  return sublevel(
      [&](double t) {
        const V3 q = p + t * d;
        return gauge(piece, q - (a + move * argmin_convex([&](double s) { return gauge(piece, q - (a + s * move)); },
                                                          0.0, 1.0, 28)));
      },
      t0, t1);
}

std::vector<sim::ConvexPiece> completed_pieces(std::span<const sim::ConvexPiece> pieces) {
  std::vector<sim::ConvexPiece> out(pieces.begin(), pieces.end());
  for (sim::ConvexPiece& p : out) {
    if (p.kind != Kind::Sphere && p.kind != Kind::Torus) continue;
    if (p.to < p.centre - 1e-12 || p.to >= p.centre + p.radius) continue;
    const bool continued = std::any_of(out.begin(), out.end(), [&](const sim::ConvexPiece& c) {
      return c.kind == Kind::Cylinder && std::abs(c.radius - p.reach()) <= 1e-12 && c.from <= p.centre + 1e-12 &&
             c.to >= p.centre + p.radius - 1e-12;
    });
    if (continued) p.to = p.centre + p.radius;
  }
  return out;
}

}  // namespace hybridctl::verification
