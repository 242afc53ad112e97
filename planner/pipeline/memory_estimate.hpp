#pragma once
// The memory planning needs at a voxel size, from the part's bounds and the machine's
// margins, before any grid is allocated (docs/hardening.md, "Memory budget").

#include <cstdint>
#include <string>

#include "config/machine.hpp"
#include "geometry/solid.hpp"

namespace hybridctl::planner {

// The region planning looks at: the design with room for overfill and the tolerance
// band, and every raw stock.
geometry::Box3 planning_region(const config::Machine& machine, const geometry::Box3& design, double tolerance);
// The voxels of the planning region on `lattice`, with 2 to spare on every side: the
// domain every primitive, atom and plan state lives in.
geometry::IndexBox planning_domain(const config::Machine& machine, const geometry::Lattice& lattice,
                                   const geometry::Box3& design, double tolerance);

// What planning allocates at voxel size h, in bytes, before the search: measured against
// peak RSS by bench/planning-peak-memory (docs/hardening.md, "Memory budget").
struct PlanningMemory {
  std::size_t primitives = 0;        // machine_primitive_count
  std::size_t other_voxel_sets = 0;  // design, tolerance core and hull, plan outcomes, operands
  double voxel_set = 0;         // one dense bit grid over the planning domain
  double voxel_sets = 0;        // the primitives' and the others'
  double atom_labels = 0;       // 4 bytes a domain voxel
  double scratch = 0;           // the dense grids of morphology (distances across an axis, sweeps)
  double total() const { return voxel_sets + atom_labels + scratch; }
};
PlanningMemory planning_memory(const geometry::Box3& part_bounds, const config::Machine& machine, double h, double tolerance);
double planning_memory_bytes(const geometry::Box3& part_bounds, const config::Machine& machine, double h, double tolerance);

// Throws InputError (exit 3) when planning at h would exceed `budget` bytes (0: the
// default budget), with the estimate and what takes it, the budget and the smallest voxel
// size that fits.
void check_planning_memory(const geometry::Box3& part_bounds, const config::Machine& machine, double h, double tolerance,
                           std::uint64_t budget, const std::string& part_name);

}  // namespace hybridctl::planner
