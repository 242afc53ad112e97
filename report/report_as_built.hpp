#pragma once
// What a dry run built against the design, for the report's deviation colour map: the
// material beyond the design and the design left empty, each split at the tolerance
// (within it, beyond it), so both directions show and what matters stands out.

#include <filesystem>

#include "plan/plan_file.hpp"

namespace hybridctl::report {

struct AsBuilt {
  geometry::Solid built;                     // on the plan's lattice, within its domain
  geometry::Solid over_within, over_beyond;  // built outside the design: within / beyond the tolerance of it
  geometry::Solid under_within, under_beyond;  // design left empty: within / deeper than the tolerance
};

// Reads `as_built_vdb` (sim serve --as-built) onto the plan's lattice. Throws
// hybridctl::InputError naming the file when it cannot be read or is on another grid.
AsBuilt as_built(const plan::PlanFile& file, const std::filesystem::path& as_built_vdb);

}  // namespace hybridctl::report
