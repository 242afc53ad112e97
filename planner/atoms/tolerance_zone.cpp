#include "planner/atoms/tolerance_zone.hpp"

#include <algorithm>

#include "geometry/morphology.hpp"

namespace hybridctl::planner {

ToleranceZone make_tolerance_zone(const geometry::Solid& design, double tolerance_mm) {
  const geometry::Solid nothing(design.lattice(), {});
  if (tolerance_mm <= 0 || design.empty()) return {design, design, nothing, nothing, std::max(0.0, tolerance_mm)};
  const geometry::Ball ball{tolerance_mm};
  ToleranceZone z{geometry::erode(design, ball), geometry::dilate(design, ball), nothing, nothing, tolerance_mm};
  z.thin = subtract(design, geometry::dilate(z.core, ball));
  z.narrow = subtract(geometry::erode(z.hull, ball), design);
  return z;
}

}  // namespace hybridctl::planner
