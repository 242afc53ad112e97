#include "planner/pipeline/memory_estimate.hpp"
#include "planner/atoms/fine_graining.hpp"

#include <algorithm>
#include <cstdio>

#include "geometry/memory_estimate.hpp"
#include "instruments/cutter.hpp"
#include "planner/primitives/bands.hpp"
#include "planner/primitives/filled.hpp"
#include "planner/primitives/machine_primitives.hpp"

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
  for (const auto& s : m.raw_stocks) region = box_hull(region, stock_bounds(s, design));
  return region;
}

geometry::IndexBox planning_domain(const config::Machine& m, const geometry::Lattice& lattice, const Box3& design,
                                   double tolerance) {
  const geometry::IndexBox region = lattice.centers_within(planning_region(m, design, tolerance));
  return {{region.lo.x - 2, region.lo.y - 2, region.lo.z - 2}, {region.hi.x + 2, region.hi.y + 2, region.hi.z + 2}};
}

namespace {

// The voxels the morphology's dense grids cover: the planning region grown by the widest
// cutter across its axis (tool sweeps keep the distances across an axis over the columns
// a cutter reaches) or, for a tool whose body narrows (a reduced neck: its sweeps take
// dilations over the tip positions), by its cutting length too.
double scratch_grid_voxels(const Box3& region, const config::Machine& m, double h) {
  double reach = 0;
  for (const auto& tool_in : m.tools) {
    const config::CuttingTool tool = instruments::with_defaults(tool_in);
    reach = std::max(reach, tool.diameter / 2);
    if (tool.shank.diameter < tool.diameter || tool.holder.diameter < tool.shank.diameter)
      reach = std::max(reach, tool.diameter / 2 + tool.flute_length);
  }
  return geometry::grid_voxels(grown(region, reach), h, 2);
}

}  // namespace

PlanningMemory planning_memory(const Box3& part_bounds, const config::Machine& m, double h, double tolerance) {
  const Box3 region = planning_region(m, part_bounds, tolerance);
  PlanningMemory mem;
  mem.primitives = machine_primitive_count(m) + max_banded_primitive_count(m) + max_filled_primitive_count(m) +
                   kMaxFineGrainedPrimitives;
  mem.voxel_set = geometry::solid_bytes(region, h, 2);
  // Design, tolerance core and hull, the plan outcomes (top_k) and two operands of a CSG step.
  mem.other_voxel_sets = 5 + std::size_t(std::max(1, m.planning.top_k));
  mem.voxel_sets = double(mem.primitives + mem.other_voxel_sets) * mem.voxel_set;
  mem.atom_labels = 4.0 * geometry::grid_voxels(region, h, 2);
  // Distances across an axis (4 bytes a voxel) and a sweep's bytes (1): one of each in use
  // at a time. bench/planning-peak-memory measures the process's peak (program included)
  // below the estimate.
  mem.scratch = (4.0 + 1.0) * scratch_grid_voxels(region, m, h);
  return mem;
}

double planning_memory_bytes(const Box3& part_bounds, const config::Machine& m, double h, double tolerance) {
  return planning_memory(part_bounds, m, h, tolerance).total();
}

void check_planning_memory(const Box3& part_bounds, const config::Machine& m, double h, double tolerance, std::uint64_t budget,
                           const std::string& part_name) {
  char voxel[32];
  std::snprintf(voxel, sizeof voxel, "%g", h);
  const PlanningMemory mem = planning_memory(part_bounds, m, h, tolerance);
  const std::string what = "planning " + part_name + " at " + voxel + " mm (" + std::to_string(mem.primitives) +
                           " primitives and " + std::to_string(mem.other_voxel_sets) + " other voxel sets of " + geometry::format_bytes(mem.voxel_set) + " each, atom labels " +
                           geometry::format_bytes(mem.atom_labels) + ", morphology's grids " +
                           geometry::format_bytes(mem.scratch) + ")";
  geometry::check_memory_budget([&](double v) { return planning_memory_bytes(part_bounds, m, v, tolerance); }, h,
                                budget ? budget : geometry::default_memory_budget(), what);
}

}  // namespace hybridctl::planner
