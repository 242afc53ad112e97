#pragma once
// A point in a work frame's XY plane, mm: the toolpath generators' 2D geometry (contours,
// wall finishing's loops).

namespace hybridctl::toolpaths {

struct Point2 {
  double x = 0, y = 0;
  friend bool operator==(const Point2&, const Point2&) = default;
};

}  // namespace hybridctl::toolpaths
