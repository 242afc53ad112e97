#pragma once
// Why a candidate plan was turned down when it was executed before being offered
// (validation/, docs/validation.md), as plan.json's `rejected` array records it
// (docs/plan-format.md). The planner keeps these records; the layer above it that runs
// the toolpaths and the material simulation finds the reasons.

#include <optional>
#include <string>
#include <vector>

#include "geometry/solid.hpp"

namespace hybridctl::plan {

// One located reason. `kind` is one of the names in docs/plan-format.md ("gouge",
// "rapid_into_material", "missing_material", "layer_skipped", ...).
struct RejectionReason {
  std::string kind;
  int action = 0;                       // 1-based action of the plan; 0: the plan as a whole
  int line = 0;                         // G-code line of the whole plan's program; 0: none
  std::string message;                  // one sentence with the figures
  std::optional<geometry::Vec3> where;  // mm, part frame
  friend bool operator==(const RejectionReason&, const RejectionReason&) = default;
};

// "action 2, line 6112: rapid into material: ... at (x, y, z) mm".
std::string describe(const RejectionReason& reason);

}  // namespace hybridctl::plan
