#pragma once
// The vectors of a design surface's samples in one setup's work frame, found by the box a
// sweep covers (verification/exact_deviation.cpp): binned in XY columns, and in each
// column sorted by their lowest point, so that a sweep finds the vectors in its height
// range by a binary search instead of visiting cells up the whole flute. A sweep on
// several threads gives each its own share of the vectors (`part` of `parts`: the ones
// whose index is part modulo parts), each share its own index, so that no thread visits
// the vectors of another.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "config/machine.hpp"
#include "geometry/solid.hpp"
#include "verification/design_surface.hpp"

namespace hybridctl::verification {

// One sample's vector in a work frame: the points point + t normal, t in [t0, t1].
// Everything a sweep reads of a vector lies in its entry, next to its neighbours in the
// column: a sweep's time goes to fetching vectors from memory, not to the geometry.
struct FrameVector {
  double z0, z1;  // the vector's lowest and highest Z
  geometry::Vec3 point, normal;
  double t0, t1;
  std::uint32_t id;  // the sample's index in DesignSurface::samples()
};

class FrameIndex {
 public:
  FrameIndex(const std::vector<SurfaceSample>& samples, config::Approach approach, std::size_t part = 0,
             std::size_t parts = 1);

  // Calls fn(vector) once for every vector whose box meets `box`.
  template <class F>
  void for_each_near(const geometry::Box3& box, F&& fn) const {
    const auto [x0, x1] = range(box.min.x - wide_, box.max.x + wide_, 0);
    const auto [y0, y1] = range(box.min.y - wide_, box.max.y + wide_, 1);
    const double from = box.min.z - tallest_;
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        const std::size_t c = column(x, y);
        const FrameVector* e = entries_.data() + start_[c];
        const FrameVector* last = entries_.data() + start_[c + 1];
        e = lower_bound(e, last, from);
        for (; e != last && e->z0 <= box.max.z; ++e) {
          if (e->z1 < box.min.z) continue;
          const double xa = e->point.x + e->t0 * e->normal.x, xb = e->point.x + e->t1 * e->normal.x;
          if (std::max(xa, xb) < box.min.x || std::min(xa, xb) > box.max.x) continue;
          const double ya = e->point.y + e->t0 * e->normal.y, yb = e->point.y + e->t1 * e->normal.y;
          if (std::max(ya, yb) < box.min.y || std::min(ya, yb) > box.max.y) continue;
          fn(*e);
        }
      }
  }

 private:
  using Entry = FrameVector;
  static const Entry* lower_bound(const Entry* first, const Entry* last, double z);
  std::pair<int, int> range(double a, double b, int axis) const {
    const double lo = axis == 0 ? lo_.x : lo_.y;
    const double fa = std::floor((a - lo) / cell_), fb = std::floor((b - lo) / cell_);
    if (fb < 0 || fa > n_[axis] - 1) return {1, 0};
    return {int(std::max(0.0, fa)), int(std::min(double(n_[axis] - 1), fb))};
  }
  std::size_t column(int x, int y) const { return std::size_t(y) * std::size_t(n_[0]) + std::size_t(x); }

  geometry::Vec3 lo_;
  double cell_ = 1, tallest_ = 0, wide_ = 0;
  int n_[2] = {1, 1};
  std::vector<std::uint32_t> start_;
  std::vector<Entry> entries_;
};

}  // namespace hybridctl::verification
