#include "planner/memory_estimate.hpp"

#include <algorithm>
#include <cstdio>

#include "geometry/memory_estimate.hpp"

namespace hybridctl::planner {
namespace {

using geometry::Box3;

Box3 grown(const Box3& b, double by) {
  return {{b.min.x - by, b.min.y - by, b.min.z - by}, {b.max.x + by, b.max.y + by, b.max.z + by}};
}

Box3 box_hull(const Box3& a, const Box3& b) {
  return {{std::min(a.min.x, b.min.x), std::min(a.min.y, b.min.y), std::min(a.min.z, b.min.z)},
          {std::max(a.max.x, b.max.x), std::max(a.max.y, b.max.y), std::max(a.max.z, b.max.z)}};
}

}  // namespace

Box3 planning_region(const config::Machine& m, const Box3& design, double tolerance) {
  double reach = tolerance;
  for (const auto& head : m.heads) reach = std::max(reach, std::max(head.bead.width, head.bead.height));
  Box3 region = grown(design, reach);
  const geometry::Vec3 c{(design.min.x + design.max.x) / 2, (design.min.y + design.max.y) / 2,
                         (design.min.z + design.max.z) / 2};
  for (const auto& s : m.raw_stocks) {
    if (s.kind == config::RawStock::Kind::Box) {
      region = box_hull(region, {{design.min.x - s.margin[0], design.min.y - s.margin[1], design.min.z - s.margin[2]},
                                 {design.max.x + s.margin[0], design.max.y + s.margin[1], design.max.z + s.margin[2]}});
    } else {
      const double r = s.bar_diameter / 2, l = s.bar_length / 2;
      const geometry::Vec3 half{s.bar_axis == config::Axis::X ? l : r, s.bar_axis == config::Axis::Y ? l : r,
                                s.bar_axis == config::Axis::Z ? l : r};
      region = box_hull(region, {{c.x - half.x, c.y - half.y, c.z - half.z}, {c.x + half.x, c.y + half.y, c.z + half.z}});
    }
  }
  return region;
}

geometry::IndexBox planning_domain(const config::Machine& m, const geometry::Lattice& lattice, const Box3& design,
                                   double tolerance) {
  const geometry::IndexBox region = lattice.centers_within(planning_region(m, design, tolerance));
  return {{region.lo.x - 2, region.lo.y - 2, region.lo.z - 2}, {region.hi.x + 2, region.hi.y + 2, region.hi.z + 2}};
}

double planning_memory_bytes(const Box3& part_bounds, const config::Machine& m, double h, double tolerance) {
  const Box3 region = planning_region(m, part_bounds, tolerance);
  const double voxels = geometry::grid_voxels(region, h, 2);
  // Primitives: per head and tool a few (orientations, modes), one per raw stock.
  const double primitives = 2.0 * double(m.heads.size() + m.tools.size()) + double(m.raw_stocks.size());
  return 4.0 * voxels + (primitives + 6) * geometry::solid_bytes(region, h, 2);
}

void check_planning_memory(const Box3& part_bounds, const config::Machine& m, double h, double tolerance, std::uint64_t budget,
                           const std::string& part_name) {
  char voxel[32];
  std::snprintf(voxel, sizeof voxel, "%g", h);
  geometry::check_memory_budget([&](double v) { return planning_memory_bytes(part_bounds, m, v, tolerance); }, h,
                                budget ? budget : geometry::default_memory_budget(),
                                "planning " + part_name + " at " + voxel + " mm");
}

}  // namespace hybridctl::planner
