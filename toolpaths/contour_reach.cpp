#include "toolpaths/contour_reach.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <unordered_map>
#include <utility>

namespace hybridctl::toolpaths {
namespace {

// A point of a chain: chain, index.
using Ref = std::pair<int, int>;

// Pulls the chains' points out, vertex by vertex; cells are voxel indices (x, y), points mm.
class EdgeReacher {
 public:
  EdgeReacher(std::vector<std::vector<Point2>>& chains, const SliceMask& region, const SliceMask& inner,
              const geometry::Lattice& lattice, EdgeReach reach, const SliceMask* wall)
      : chains_(chains), region_(region), inner_(inner), wall_(wall), h_(lattice.voxel_size),
        ox_(lattice.origin.x), oy_(lattice.origin.y),
        // Room for the G-code's rounding (0.0001 mm) and the simulator's tie rule (a voxel
        // is laid when its centre lies inside the bead).
        margin_(0.01 * lattice.voxel_size),
        cover_(reach.cover - margin_), clear_(reach.clear + margin_) {
    for (int c = 0; c < int(chains_.size()); ++c) {
      const auto& ch = chains_[c];
      closed_.push_back(ch.size() >= 3 && ch.front().x == ch.back().x && ch.front().y == ch.back().y);
      for (int i = 0; i < int(ch.size()); ++i) by_cell_[key(cell_of(ch[i]))].push_back({c, i});
    }
  }

  int run() {
    // A pull may leave a cell another point was to reach: a few rounds settle it.
    for (int round = 0; round < 3; ++round) {
      const std::vector<Point2> cells = uncovered();
      if (cells.empty()) return 0;
      std::map<Ref, std::vector<Point2>> wants;
      for (const Point2& c : cells) {
        const Ref r = nearest_point(c);
        if (r.first >= 0) wants[r].push_back(c);
      }
      for (const auto& [r, targets] : wants) pull(r, targets);
    }
    return int(uncovered().size());
  }

 private:
  static long long key(Cell c) { return (static_cast<long long>(c.y) << 32) ^ static_cast<unsigned int>(c.x); }
  Cell cell_of(Point2 p) const { return {int(std::floor((p.x - ox_) / h_)), int(std::floor((p.y - oy_) / h_))}; }
  Point2 centre(int x, int y) const { return {ox_ + (x + 0.5) * h_, oy_ + (y + 0.5) * h_}; }
  bool outside(int x, int y) const { return !region_.at(x, y) && !(wall_ && wall_->at(x, y)); }

  // The chain points whose original cells lie within `radius` mm (plus a voxel: points
  // move by less than one) of p.
  template <class Fn>
  void near_points(Point2 p, double radius, Fn fn) const {
    const Cell c = cell_of(p);
    const int n = int(std::ceil(radius / h_)) + 2;
    for (int y = c.y - n; y <= c.y + n; ++y)
      for (int x = c.x - n; x <= c.x + n; ++x) {
        const auto it = by_cell_.find(key({x, y}));
        if (it == by_cell_.end()) continue;
        for (const Ref& r : it->second) fn(r);
      }
  }

  static double segment_distance(Point2 p, Point2 a, Point2 b) {
    const double abx = b.x - a.x, aby = b.y - a.y, ab2 = abx * abx + aby * aby;
    const double t = ab2 > 0 ? std::clamp(((p.x - a.x) * abx + (p.y - a.y) * aby) / ab2, 0.0, 1.0) : 0.0;
    return std::hypot(p.x - (a.x + t * abx), p.y - (a.y + t * aby));
  }

  int prev(const Ref& r) const {
    if (r.second > 0) return r.second - 1;
    return closed_[r.first] ? int(chains_[r.first].size()) - 2 : -1;
  }
  int next(const Ref& r) const {
    const int n = int(chains_[r.first].size());
    if (r.second + 1 < n) return r.second + 1;
    return closed_[r.first] ? 1 : -1;
  }

  // Distance from p to the chains near it (their segments).
  double chain_distance(Point2 p) const {
    double best = std::numeric_limits<double>::infinity();
    near_points(p, cover_, [&](const Ref& r) {
      const auto& ch = chains_[r.first];
      const int j = next(r);
      best = std::min(best, j >= 0 ? segment_distance(p, ch[r.second], ch[j]) : std::hypot(p.x - ch[r.second].x, p.y - ch[r.second].y));
    });
    return best;
  }

  Ref nearest_point(Point2 p) const {
    Ref best{-1, -1};
    double d = std::numeric_limits<double>::infinity();
    near_points(p, cover_ + h_, [&](const Ref& r) {
      const Point2 q = chains_[r.first][r.second];
      const double e = std::hypot(p.x - q.x, p.y - q.y);
      if (e < d) d = e, best = r;
    });
    return best;
  }

  // The cells of the region outside `inner` that no chain reaches.
  std::vector<Point2> uncovered() const {
    std::vector<Point2> out;
    for (int y = region_.y0(); y < region_.y0() + region_.ny(); ++y)
      for (int x = region_.x0(); x < region_.x0() + region_.nx(); ++x)
        if (region_.at(x, y) && !inner_.at(x, y) && chain_distance(centre(x, y)) > cover_) out.push_back(centre(x, y));
    return out;
  }

  // Distance from p to the nearest centre of a cell outside (capped at clear_).
  double clearance(Point2 p) const {
    const Cell c = cell_of(p);
    const int n = int(std::ceil(clear_ / h_)) + 1;
    double best = clear_;
    for (int y = c.y - n; y <= c.y + n; ++y)
      for (int x = c.x - n; x <= c.x + n; ++x)
        if (outside(x, y)) {
          const Point2 q = centre(x, y);
          best = std::min(best, std::hypot(p.x - q.x, p.y - q.y));
        }
    return best;
  }
  // The least clearance along the segment, sampled every eighth of a voxel.
  double clearance(Point2 a, Point2 b) const {
    const int steps = 1 + int(std::ceil(std::hypot(b.x - a.x, b.y - a.y) / (h_ / 8)));
    double best = clear_;
    for (int s = 0; s <= steps; ++s) {
      const double f = double(s) / steps;
      best = std::min(best, clearance({a.x + f * (b.x - a.x), a.y + f * (b.y - a.y)}));
    }
    return best;
  }
  // The least clearance of the segments at point r when it lies at q.
  double clearance_at(const Ref& r, Point2 q) const {
    const auto& ch = chains_[r.first];
    double best = clearance(q);
    if (const int i = prev(r); i >= 0) best = std::min(best, clearance(ch[i], q));
    if (const int j = next(r); j >= 0) best = std::min(best, clearance(q, ch[j]));
    return best;
  }

  void place(const Ref& r, Point2 q) {
    auto& ch = chains_[r.first];
    ch[r.second] = q;
    if (closed_[r.first] && (r.second == 0 || r.second + 1 == int(ch.size()))) ch.front() = ch.back() = q;
  }

  // Moves point r towards the farthest of `targets` until it is within cover of it, as far
  // as the clearance allows (never below what the chain had there before).
  void pull(const Ref& r, const std::vector<Point2>& targets) {
    const double floor_clearance = std::min(clear_, clearance_at(r, chains_[r.first][r.second]));
    for (int step = 0; step < 4; ++step) {
      const Point2 p = chains_[r.first][r.second];
      const Point2* far = nullptr;
      double d = cover_;
      for (const Point2& t : targets)
        if (const double e = std::hypot(t.x - p.x, t.y - p.y); e > d) d = e, far = &t;
      if (!far) return;
      const Point2 goal{far->x + (p.x - far->x) * (cover_ / d), far->y + (p.y - far->y) * (cover_ / d)};
      auto at = [&](double s) { return Point2{p.x + s * (goal.x - p.x), p.y + s * (goal.y - p.y)}; };
      double lo = 0, hi = 1;
      if (clearance_at(r, at(1)) >= floor_clearance) {
        lo = 1;
      } else {
        for (int i = 0; i < 12; ++i) {
          const double mid = 0.5 * (lo + hi);
          (clearance_at(r, at(mid)) >= floor_clearance ? lo : hi) = mid;
        }
      }
      if (lo <= 1e-6) return;
      place(r, at(lo));
      if (lo < 1) return;
    }
  }

  std::vector<std::vector<Point2>>& chains_;
  const SliceMask& region_;
  const SliceMask& inner_;
  const SliceMask* wall_;
  double h_, ox_, oy_, margin_, cover_, clear_;
  std::vector<bool> closed_;
  std::unordered_map<long long, std::vector<Ref>> by_cell_;
};

}  // namespace

int reach_edges(std::vector<std::vector<Point2>>& chains, const SliceMask& region, const SliceMask& inner,
                const geometry::Lattice& lattice, EdgeReach reach, const SliceMask* wall) {
  if (chains.empty()) return 0;
  return EdgeReacher(chains, region, inner, lattice, reach, wall).run();
}

std::vector<std::vector<Point2>> voxel_contour(const SliceMask& region, const SliceMask& wall,
                                               const geometry::Lattice& lattice, double inset, double min_length,
                                               EdgeReach reach, int& out_of_reach) {
  const double h = lattice.voxel_size;
  const SliceMask inner = shrink_by_disc(region, inset / h);
  std::vector<std::vector<Point2>> chains;
  for (const auto& chain : trace_chains(boundary_cells(inner))) {
    std::vector<Point2> points;
    double length = 0;
    for (const Cell& cell : chain) {
      const Point2 c{lattice.origin.x + (cell.x + 0.5) * h, lattice.origin.y + (cell.y + 0.5) * h};
      if (!points.empty()) length += std::hypot(c.x - points.back().x, c.y - points.back().y);
      points.push_back(c);
    }
    if (points.size() >= 2 && length >= min_length - 1e-9) chains.push_back(std::move(points));
  }
  out_of_reach = reach_edges(chains, region, inner, lattice, reach, &wall);
  for (auto& chain : chains) chain = without_collinear(chain);
  return chains;
}

}  // namespace hybridctl::toolpaths
