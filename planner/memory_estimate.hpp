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

// Bytes planning takes at voxel size h: the atom labels (4 bytes a domain voxel) and the
// dense solids alive at once (design, tolerance zone, one per primitive, plan outcomes).
double planning_memory_bytes(const geometry::Box3& part_bounds, const config::Machine& machine, double h, double tolerance);

// Throws InputError (exit 3) when planning at h would exceed `budget` bytes (0: the
// default budget), with the estimate, the budget and the smallest voxel size that fits.
void check_planning_memory(const geometry::Box3& part_bounds, const config::Machine& machine, double h, double tolerance,
                           std::uint64_t budget, const std::string& part_name);

}  // namespace hybridctl::planner
