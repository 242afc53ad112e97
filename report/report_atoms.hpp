#pragma once
// The atoms' voxels for the report, recomputed exactly from the primitives and the atom
// codes plan.json lists (docs/plan-format.md, "Atoms"): every voxel of the domain belongs
// to the atom whose code is its membership in P1..Pn.

#include <string>
#include <vector>

#include "plan/plan_file.hpp"

namespace hybridctl::report {

struct AtomSolids {
  geometry::Solid must_in, must_out, free;  // the union of the atoms of each class
  std::vector<int> violating_ids;            // atom ids, in the order asked for
  std::vector<geometry::Solid> violating;    // each violating atom's voxels
};

// `codes[a]` and `classes[a]` of atom a as plan.json has them; `violating` the atom ids
// to keep one by one. Throws hybridctl::InputError when a code's length is not the number
// of primitives.
AtomSolids atom_solids(const plan::PlanFile& file, const std::vector<std::string>& codes,
                       const std::vector<std::string>& classes, const std::vector<int>& violating);

}  // namespace hybridctl::report
