#include "sim/sweep.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace hybridctl::sim {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Voxel indices are clamped to this before conversion to int.
constexpr double kIndexLimit = double(1 << 29);

double sq(double v) { return v * v; }

struct Interval {
  double lo = kInf, hi = -kInf;
  bool empty() const { return !(lo <= hi); }
  void add(double l, double h) {
    lo = std::min(lo, l);
    hi = std::max(hi, h);
  }
};

// The X extent of the points (x, y, z) within r of the segment p-q: a capsule, the union
// of the balls at both ends and the cylinder between them. The capsule is convex, so the
// hull of the three parts' intervals is its interval.
Interval capsule_row(const Vec3& p, const Vec3& q, double r, double y, double z) {
  Interval out;
  const double r2 = r * r;
  auto ball = [&](const Vec3& c) {
    const double m = r2 - sq(y - c.y) - sq(z - c.z);
    if (m >= 0) {
      const double s = std::sqrt(m);
      out.add(c.x - s, c.x + s);
    }
  };
  ball(p);
  if (p == q) return out;
  ball(q);
  const double vx = q.x - p.x, vy = q.y - p.y, vz = q.z - p.z;
  const double wy = y - p.y, wz = z - p.z;
  const double a = vy * vy + vz * vz;  // |v|^2 without its X part
  const double l2 = vx * vx + a;
  if (a == 0) {  // the segment runs along X: the row is parallel to it
    if (wy * wy + wz * wz <= r2) out.add(std::min(p.x, q.x), std::max(p.x, q.x));
    return out;
  }
  // Distance from (p.x + X, y, z) to the segment's line, squared, is quadratic in X:
  // its sublevel set r^2 is [xc - hw, xc + hw]; the foot of the perpendicular must lie
  // on the segment: vx X + along in [0, l2].
  const double cross = wy * vz - wz * vy;
  const double g = r2 - cross * cross / a;
  if (g < 0) return out;
  const double along = wy * vy + wz * vz;
  const double xc = vx * along / a;
  const double hw = std::sqrt(l2 / a * g);
  double lo = xc - hw, hi = xc + hw;
  if (vx == 0) {
    if (along < 0 || along > l2) return out;
  } else {
    double s0 = -along / vx, s1 = (l2 - along) / vx;
    if (s0 > s1) std::swap(s0, s1);
    lo = std::max(lo, s0);
    hi = std::min(hi, s1);
  }
  if (lo <= hi) out.add(p.x + lo, p.x + hi);
  return out;
}

Vec3 flat(const Vec3& v) { return {v.x, v.y, 0}; }

void require_radius(double r, const char* what) {
  if (!(r >= 0) || !std::isfinite(r))
    throw std::invalid_argument(std::string(what) + " radius must be a finite number >= 0, got " + std::to_string(r));
}

}  // namespace

double ConvexPiece::reach() const {
  switch (kind) {
    case Kind::Torus: return ring + radius;
    default: return radius;
  }
}

std::vector<ConvexPiece> pieces_of(std::span<const geometry::AxialSection> sections) {
  using S = geometry::AxialSection::Kind;
  std::vector<ConvexPiece> out;
  for (const geometry::AxialSection& s : sections) {
    require_radius(s.radius, "section");
    if (std::isnan(s.from) || std::isnan(s.to) || std::isinf(s.from))
      throw std::invalid_argument("section extent must be numbers, `from` finite");
    if (std::isinf(s.to) && s.kind != S::Cylinder)
      throw std::invalid_argument("only a cylinder section may be infinite");
    ConvexPiece p;
    p.from = s.from;
    p.to = s.to;
    p.radius = s.radius;
    switch (s.kind) {
      case S::Cylinder: p.kind = ConvexPiece::Kind::Cylinder; break;
      case S::Sphere:
        p.kind = ConvexPiece::Kind::Sphere;
        p.centre = s.centre;
        break;
      case S::Torus:
        require_radius(s.ring, "torus ring");
        p.kind = s.ring > 0 ? ConvexPiece::Kind::Torus : ConvexPiece::Kind::Sphere;
        p.centre = s.centre;
        p.ring = s.ring;
        break;
    }
    if (p.kind != ConvexPiece::Kind::Cylinder) {
      p.from = std::max(p.from, p.centre - p.radius);
      p.to = std::min(p.to, p.centre + p.radius);
    }
    if (p.from <= p.to) out.push_back(p);
  }
  return out;
}

std::vector<ConvexPiece> pieces_of(const Bead& bead) {
  if (!(bead.width > 0) || !(bead.height > 0) || !std::isfinite(bead.width) || !std::isfinite(bead.height))
    throw std::invalid_argument("bead width and height must be positive, got " + std::to_string(bead.width) + " x " +
                                std::to_string(bead.height));
  ConvexPiece p;
  p.from = 0;
  p.to = bead.height;
  p.radius = bead.width / 2;
  if (bead.shape != config::BeadShape::Ellipsoid) {
    p.kind = ConvexPiece::Kind::Cylinder;
    return {p};
  }
  p.kind = ConvexPiece::Kind::Ellipsoid;
  p.centre = bead.height / 2;
  p.half_height = bead.height / 2;
  // The molten bead wets what it is laid on and fills the valleys between the tracks and
  // layers below: below its widest line it is as wide as that line (docs/simulation.md).
  // Ellipses alone leave a void where four overlapping beads meet, which no real
  // deposit has.
  ConvexPiece lower;
  lower.kind = ConvexPiece::Kind::Cylinder;
  lower.from = 0;
  lower.to = bead.height / 2;
  lower.radius = bead.width / 2;
  return {p, lower};
}

PieceSweep::PieceSweep(const ConvexPiece& piece, const Segment& segment, const geometry::Lattice& lattice)
    : piece_(piece),
      a_(segment.from),
      b_(segment.to),
      d_{segment.to.x - segment.from.x, segment.to.y - segment.from.y, segment.to.z - segment.from.z},
      h_(lattice.voxel_size),
      slack_(kTieSlack * lattice.voxel_size),
      origin_(lattice.origin) {
  level_ = d_.z == 0;
  vertical_ = d_.x == 0 && d_.y == 0;
}

geometry::IndexBox PieceSweep::bounds(const geometry::IndexBox& clip) const {
  if (std::isinf(piece_.to) && clip.empty())
    throw std::invalid_argument("the sweep of an infinite body needs a clip box");
  const double reach = piece_.reach() + slack_;
  auto lo = [&](double v, double o) { return int(std::clamp(std::ceil((v - o) / h_ - 0.5), -kIndexLimit, kIndexLimit)); };
  auto hi = [&](double v, double o) {
    return int(std::clamp(std::floor((v - o) / h_ - 0.5), -kIndexLimit, kIndexLimit)) + 1;
  };
  geometry::IndexBox box{
      {lo(std::min(a_.x, b_.x) - reach, origin_.x), lo(std::min(a_.y, b_.y) - reach, origin_.y),
       lo(std::min(a_.z, b_.z) + piece_.from - slack_, origin_.z)},
      {hi(std::max(a_.x, b_.x) + reach, origin_.x), hi(std::max(a_.y, b_.y) + reach, origin_.y),
       hi(std::max(a_.z, b_.z) + piece_.to + slack_, origin_.z)}};
  if (!clip.empty()) box = geometry::box_intersection(box, clip);
  return box.empty() ? geometry::IndexBox{} : box;
}

XRange PieceSweep::to_voxels(double lo, double hi) const {
  // ceil and floor by integer conversion (truncation) and a correction: per row, this is
  // hot, and without SSE4.1 the library's rounding is a slow sequence.
  const double a = std::clamp((lo - origin_.x) / h_ - 0.5, -kIndexLimit, kIndexLimit);
  const double b = std::clamp((hi - origin_.x) / h_ - 0.5, -kIndexLimit, kIndexLimit);
  int ia = int(a), ib = int(b);
  if (ia < a) ++ia;
  if (ib > b) --ib;
  return {ia, ib + 1};
}

XRange PieceSweep::row(int y, int z) const {
  const double yc = origin_.y + (y + 0.5) * h_, zc = origin_.z + (z + 0.5) * h_;
  // Positions t in [ta, tb] put the row's height inside the piece's slab.
  const double zrel = zc - a_.z;  // height of the row above the segment's start
  const double slab_lo = piece_.from - slack_, slab_hi = piece_.to + slack_;
  double ta = 0, tb = 1;
  if (level_) {
    if (zrel < slab_lo || zrel > slab_hi) return {};
  } else {
    double t1 = (zrel - slab_hi) / d_.z, t2 = (zrel - slab_lo) / d_.z;
    if (t1 > t2) std::swap(t1, t2);
    ta = std::max(0.0, t1);
    tb = std::min(1.0, t2);
    if (!(ta <= tb)) return {};
  }
  auto at = [&](double t) {
    if (t == 0) return a_;
    if (t == 1) return b_;
    return Vec3{a_.x + t * d_.x, a_.y + t * d_.y, a_.z + t * d_.z};
  };
  const Vec3 s0 = at(ta), s1 = at(tb);
  Interval iv;
  switch (piece_.kind) {
    case ConvexPiece::Kind::Cylinder:
      iv = capsule_row(flat(s0), flat(s1), piece_.radius + slack_, yc, 0);
      break;
    case ConvexPiece::Kind::Sphere: {
      const Vec3 c0{s0.x, s0.y, s0.z + piece_.centre}, c1{s1.x, s1.y, s1.z + piece_.centre};
      iv = capsule_row(c0, c1, piece_.radius + slack_, yc, zc);
      break;
    }
    case ConvexPiece::Kind::Ellipsoid: {
      // Scaling Z by radius / half_height turns the ellipsoid into a ball.
      const double k = piece_.radius / piece_.half_height;
      const Vec3 c0{s0.x, s0.y, (s0.z + piece_.centre) * k}, c1{s1.x, s1.y, (s1.z + piece_.centre) * k};
      iv = capsule_row(c0, c1, piece_.radius + slack_, yc, zc * k);
      break;
    }
    case ConvexPiece::Kind::Torus: {
      const double tube = piece_.radius + slack_;
      auto radius_at = [&](double zp) {
        return piece_.ring + std::sqrt(std::max(0.0, tube * tube - sq(zp - piece_.centre)));
      };
      // Heights of the row in the tool frame at both ends of the sub-segment.
      const double za = zrel - ta * d_.z, zb = zrel - tb * d_.z;
      const double zmin = std::min(za, zb), zmax = std::max(za, zb);
      const double outer_r = radius_at(std::clamp(piece_.centre, zmin, zmax));
      const Interval outer = capsule_row(flat(s0), flat(s1), outer_r, yc, 0);
      if (level_ || vertical_ || outer.empty()) {
        iv = outer;
        break;
      }
      // A ramp: the radius varies along the sub-segment. Voxels between the sweeps of
      // the smallest and the largest radius are decided one by one; the row's interval
      // is convex, so each band needs only a binary search for its boundary voxel.
      const XRange out_v = to_voxels(outer.lo, outer.hi);
      if (out_v.empty()) return {};
      const Interval inner = capsule_row(flat(s0), flat(s1), std::min(radius_at(za), radius_at(zb)), yc, 0);
      XRange in_v = inner.empty() ? XRange{} : to_voxels(inner.lo, inner.hi);
      in_v.x0 = std::max(in_v.x0, out_v.x0);
      in_v.x1 = std::min(in_v.x1, out_v.x1);
      auto inside = [&](int x) { return torus_contains(origin_.x + (x + 0.5) * h_, yc, zc, ta, tb); };
      int first, last;
      if (in_v.empty()) {
        first = out_v.x0;
        while (first < out_v.x1 && !inside(first)) ++first;
        if (first == out_v.x1) return {};
        last = out_v.x1 - 1;
        while (last > first && !inside(last)) --last;
      } else {
        // Inside is monotone across each band: binary search for the boundary voxel.
        int lo = out_v.x0, hi = in_v.x0;  // the answer is in [lo, hi]; hi is inside
        while (lo < hi) {
          const int mid = lo + (hi - lo) / 2;
          if (inside(mid)) hi = mid; else lo = mid + 1;
        }
        first = lo;
        lo = in_v.x1 - 1;
        hi = out_v.x1 - 1;  // the answer is in [lo, hi]; lo is inside
        while (lo < hi) {
          const int mid = hi - (hi - lo) / 2;
          if (inside(mid)) lo = mid; else hi = mid - 1;
        }
        last = lo;
      }
      return {first, last + 1};
    }
  }
  if (iv.empty()) return {};
  return to_voxels(iv.lo, iv.hi);
}

bool PieceSweep::torus_contains(double x, double y, double z, double ta, double tb) const {
  // F(t) = squared distance from the point to the torus's core disc placed at t: convex
  // in t (distance to a convex set along a line), differentiable since ring > 0.
  const double qx0 = x - a_.x, qy0 = y - a_.y, qz0 = z - a_.z - piece_.centre;
  const double ring = piece_.ring;
  auto eval = [&](double t, double& f, double& df) {
    const double qx = qx0 - t * d_.x, qy = qy0 - t * d_.y, qz = qz0 - t * d_.z;
    const double rho = std::hypot(qx, qy);
    const double e = rho - ring;
    if (e > 0) {
      f = e * e + qz * qz;
      df = -2 * e * (qx * d_.x + qy * d_.y) / rho - 2 * qz * d_.z;
    } else {
      f = qz * qz;
      df = -2 * qz * d_.z;
    }
  };
  const double tube = piece_.radius + slack_, limit = tube * tube;
  double f_lo, df_lo, f_hi, df_hi;
  eval(ta, f_lo, df_lo);
  if (f_lo <= limit) return true;
  if (df_lo >= 0) return false;
  eval(tb, f_hi, df_hi);
  if (f_hi <= limit) return true;
  if (df_hi <= 0) return false;
  // Bisection on the sign of F'. The tangents at both ends bound F from below; once
  // that bound clears the limit, the point is outside.
  double lo = ta, hi = tb;
  for (int i = 0; i < 200; ++i) {
    const double cross = (f_hi - f_lo + df_lo * lo - df_hi * hi) / (df_lo - df_hi);
    if (f_lo + df_lo * (cross - lo) > limit) return false;
    const double mid = 0.5 * (lo + hi);
    if (mid <= lo || mid >= hi) break;
    double f, df;
    eval(mid, f, df);
    if (f <= limit) return true;
    if (df > 0) {
      hi = mid;
      f_hi = f;
      df_hi = df;
    } else {
      lo = mid;
      f_lo = f;
      df_lo = df;
    }
  }
  return false;
}

geometry::Solid swept_volume(std::span<const ConvexPiece> pieces, const Segment& segment,
                             const geometry::Lattice& lattice, const geometry::IndexBox& domain) {
  geometry::Solid out(lattice, domain);
  for (const ConvexPiece& piece : pieces) {
    const PieceSweep sweep(piece, segment, lattice);
    const geometry::IndexBox box = sweep.bounds(domain);
    for (int z = box.lo.z; z < box.hi.z; ++z)
      for (int y = box.lo.y; y < box.hi.y; ++y) {
        const XRange r = sweep.row(y, z);
        const int x0 = std::max(r.x0, domain.lo.x), x1 = std::min(r.x1, domain.hi.x);
        if (x0 < x1) out.set_run(y, z, x0, x1);
      }
  }
  return out;
}

}  // namespace hybridctl::sim
