#include "planner/deviation.hpp"

#include <algorithm>

#include "geometry/morphology.hpp"

namespace hybridctl::planner {

Deviation measure_deviation(const geometry::Solid& made, const geometry::Solid& design,
                            const geometry::IndexBox& domain, double tolerance) {
  const geometry::Solid over = subtract(made, design), under = subtract(design, made);
  const double half = design.voxel_size() / 2;
  Deviation d;
  d.over_volume = over.volume();
  d.under_volume = under.volume();
  d.worst_over = std::max(0.0, geometry::farthest_distance(over, design) - (over.empty() ? 0 : half));
  d.worst_under =
      std::max(0.0, geometry::farthest_distance(under, complement(design, domain)) - (under.empty() ? 0 : half));
  d.worst_distance = std::max(d.worst_over, d.worst_under);
  d.within_tolerance = d.worst_distance <= tolerance + 1e-9;
  return d;
}

}  // namespace hybridctl::planner
