#pragma once
// A point in a work frame's XY plane, mm: the toolpath generators' 2D geometry (contours,
// wall finishing's loops).

#include <cmath>
#include <vector>

namespace hybridctl::toolpaths {

struct Point2 {
  double x = 0, y = 0;
  friend bool operator==(const Point2&, const Point2&) = default;
};

// The polyline without the middle point of three collinear ones that run on in one
// direction (a chain of cell centres along a row, a densified edge).
inline std::vector<Point2> without_collinear(const std::vector<Point2>& line) {
  std::vector<Point2> out;
  for (const Point2& c : line) {
    if (out.size() >= 2) {
      const Point2 a = out[out.size() - 2], b = out.back();
      const double cross = (b.x - a.x) * (c.y - b.y) - (b.y - a.y) * (c.x - b.x);
      const double dot = (b.x - a.x) * (c.x - b.x) + (b.y - a.y) * (c.y - b.y);
      if (std::abs(cross) <= 1e-9 * std::hypot(c.x - a.x, c.y - a.y) && dot > 0) out.pop_back();
    }
    out.push_back(c);
  }
  return out;
}

}  // namespace hybridctl::toolpaths
