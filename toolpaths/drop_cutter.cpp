#include "toolpaths/drop_cutter.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "instruments/cutter.hpp"

namespace hybridctl::toolpaths {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

Eigen::Vector3d eig(const geometry::Vec3& v) { return {v.x, v.y, v.z}; }

// Inside the triangle's XY projection (boundary included, with a relative slack).
bool inside_xy(const Eigen::Vector2d& c, const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& d) {
  auto cross = [](const Eigen::Vector2d& u, const Eigen::Vector2d& v) { return u.x() * v.y() - u.y() * v.x(); };
  const double area = cross(b - a, d - a);
  if (std::abs(area) < 1e-18) return false;
  const double s = cross(b - a, c - a) / area, t = cross(d - b, c - b) / area, u = cross(a - d, c - d) / area;
  constexpr double slack = -1e-12;
  return s >= slack && t >= slack && u >= slack;
}

}  // namespace

double CutterShape::height_at(double d) const {
  if (d > radius) return kInf;
  const double flat = radius - corner_radius;  // the flat bottom's radius
  if (d <= flat) return 0;
  const double e = d - flat;
  return corner_radius - std::sqrt(std::max(0.0, corner_radius * corner_radius - e * e));
}

CutterShape cutter_shape(const config::CuttingTool& tool_in) {
  const config::CuttingTool tool = instruments::with_defaults(tool_in);
  CutterShape s;
  s.radius = tool.diameter / 2;
  switch (tool.type) {
    case config::ToolType::Flat: s.corner_radius = 0; break;
    case config::ToolType::Ball: s.corner_radius = s.radius; break;
    case config::ToolType::Bull: s.corner_radius = tool.corner_radius; break;
  }
  return s;
}

double scallop_step_over(const CutterShape& shape, double scallop) {
  if (!(scallop > 0)) throw std::invalid_argument("scallop_step_over: the scallop height must be > 0");
  const double r = shape.corner_radius;
  if (r <= 0) return 2 * shape.radius;
  const double h = std::min(scallop, r);
  return 2 * std::sqrt(2 * r * h - h * h);
}

DropCutter::DropCutter(std::shared_ptr<const std::vector<geometry::Triangle>> mesh, CutterShape shape)
    : mesh_(std::move(mesh)), shape_(shape) {
  if (!mesh_) mesh_ = std::make_shared<const std::vector<geometry::Triangle>>();
  if (!(shape_.radius > 0) || shape_.corner_radius < 0 || shape_.corner_radius > shape_.radius)
    throw std::invalid_argument("DropCutter: the cutter needs a radius > 0 and a corner radius in [0, radius]");
  if (mesh_->empty()) return;
  double x1 = -kInf, y1 = -kInf;
  x0_ = kInf, y0_ = kInf;
  for (const auto& t : *mesh_)
    for (const auto& v : t) x0_ = std::min(x0_, v.x), y0_ = std::min(y0_, v.y), x1 = std::max(x1, v.x), y1 = std::max(y1, v.y);
  cell_ = std::max(shape_.radius, 0.5);
  nx_ = int(std::floor((x1 - x0_) / cell_)) + 1;
  ny_ = int(std::floor((y1 - y0_) / cell_)) + 1;
  buckets_.assign(std::size_t(nx_) * std::size_t(ny_), {});
  for (std::size_t i = 0; i < mesh_->size(); ++i) {
    const auto& t = (*mesh_)[i];
    const double tx0 = std::min({t[0].x, t[1].x, t[2].x}), tx1 = std::max({t[0].x, t[1].x, t[2].x});
    const double ty0 = std::min({t[0].y, t[1].y, t[2].y}), ty1 = std::max({t[0].y, t[1].y, t[2].y});
    const int cx0 = int(std::floor((tx0 - x0_) / cell_)), cx1 = std::min(nx_ - 1, int(std::floor((tx1 - x0_) / cell_)));
    const int cy0 = int(std::floor((ty0 - y0_) / cell_)), cy1 = std::min(ny_ - 1, int(std::floor((ty1 - y0_) / cell_)));
    for (int y = cy0; y <= cy1; ++y)
      for (int x = cx0; x <= cx1; ++x) buckets_[std::size_t(y) * std::size_t(nx_) + std::size_t(x)].push_back(int(i));
  }
  seen_.assign(mesh_->size(), 0);
}

double DropCutter::tip_height(Point2 p) const {
  if (mesh_->empty()) return -kInf;
  const double R = shape_.radius, r = shape_.corner_radius, flat = R - r;
  const int cx0 = std::max(0, int(std::floor((p.x - R - x0_) / cell_)));
  const int cx1 = std::min(nx_ - 1, int(std::floor((p.x + R - x0_) / cell_)));
  const int cy0 = std::max(0, int(std::floor((p.y - R - y0_) / cell_)));
  const int cy1 = std::min(ny_ - 1, int(std::floor((p.y + R - y0_) / cell_)));
  if (cx0 > cx1 || cy0 > cy1) return -kInf;
  if (++stamp_ == 0) {
    std::fill(seen_.begin(), seen_.end(), 0);
    stamp_ = 1;
  }
  const Eigen::Vector2d c(p.x, p.y);
  double best = -kInf;
  auto vertex = [&](const Eigen::Vector3d& v) {
    const double d = (v.head<2>() - c).norm();
    if (d <= R) best = std::max(best, v.z() - shape_.height_at(d));
  };
  auto edge = [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    const Eigen::Vector2d dir = b.head<2>() - a.head<2>(), w = a.head<2>() - c;
    const double l2 = dir.squaredNorm();
    if (l2 < 1e-24) return;
    const double wd = w.dot(dir), disc = wd * wd - l2 * (w.squaredNorm() - R * R);
    if (disc <= 0) return;
    const double sq = std::sqrt(disc);
    double lo = std::max(0.0, (-wd - sq) / l2), hi = std::min(1.0, (-wd + sq) / l2);
    if (!(lo < hi)) return;
    // No higher than the edge's top less the lower surface at its nearest approach (f
    // increases with the distance): most edges are settled here.
    const double nearest = (w + std::clamp(-wd / l2, lo, hi) * dir).norm();
    if (std::max(a.z(), b.z()) - shape_.height_at(std::min(R, nearest)) <= best) return;
    auto g = [&](double t) {
      const double d = std::min(R, (w + t * dir).norm());
      return a.z() + t * (b.z() - a.z()) - shape_.height_at(d);
    };
    constexpr double phi = 0.6180339887498949;
    double x1 = hi - phi * (hi - lo), x2 = lo + phi * (hi - lo), g1 = g(x1), g2 = g(x2);
    while (hi - lo > 1e-10) {
      if (g1 < g2) {
        lo = x1, x1 = x2, g1 = g2, x2 = lo + phi * (hi - lo), g2 = g(x2);
      } else {
        hi = x2, x2 = x1, g2 = g1, x1 = hi - phi * (hi - lo), g1 = g(x1);
      }
    }
    best = std::max({best, g1, g2, g(lo), g(hi)});
  };
  for (int y = cy0; y <= cy1; ++y)
    for (int x = cx0; x <= cx1; ++x)
      for (const int i : buckets_[std::size_t(y) * std::size_t(nx_) + std::size_t(x)]) {
        if (seen_[std::size_t(i)] == stamp_) continue;
        seen_[std::size_t(i)] = stamp_;
        const auto& t = (*mesh_)[std::size_t(i)];
        // The cutter's lower surface is never below its tip: nothing higher than best here.
        if (std::max({t[0].z, t[1].z, t[2].z}) <= best) continue;
        const double tx0 = std::min({t[0].x, t[1].x, t[2].x}), tx1 = std::max({t[0].x, t[1].x, t[2].x});
        const double ty0 = std::min({t[0].y, t[1].y, t[2].y}), ty1 = std::max({t[0].y, t[1].y, t[2].y});
        if (tx0 > p.x + R || tx1 < p.x - R || ty0 > p.y + R || ty1 < p.y - R) continue;
        const Eigen::Vector3d a = eig(t[0]), b = eig(t[1]), d = eig(t[2]);
        Eigen::Vector3d n = (b - a).cross(d - a);
        const double nn = n.norm();
        if (nn > 0) {
          n /= nn;
          if (n.z() < 0) n = -n;
          if (n.z() > 1e-12) {
            const double s = n.head<2>().norm();
            Eigen::Vector2d at = c;
            double rise = 0;  // f at the contact
            if (s > 1e-15) {
              const Eigen::Vector2d uphill = -n.head<2>() / s;
              const double dist = r > 0 ? flat + r * s : R;
              at = c + dist * uphill;
              rise = r > 0 ? r - r * n.z() : 0;
            }
            if (inside_xy(at, a.head<2>(), b.head<2>(), d.head<2>())) {
              // The plane: n . (q - a) = 0.
              const double z = a.z() - (n.x() * (at.x() - a.x()) + n.y() * (at.y() - a.y())) / n.z();
              best = std::max(best, z - rise);
            }
          }
        }
        vertex(a), vertex(b), vertex(d);
        edge(a, b), edge(b, d), edge(d, a);
      }
  return best;
}

}  // namespace hybridctl::toolpaths
