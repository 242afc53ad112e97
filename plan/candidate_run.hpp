#pragma once
// What executing a candidate plan from the raw stock showed (validation/,
// docs/validation.md): the contract between validation, which runs the plan's G-code on
// the simulated machine, and the planner, which learns from it what its primitives do not
// do (planner/pipeline/shortfall.hpp). In plan.json's terms, so that neither needs the other.

#include <cstddef>
#include <functional>
#include <optional>
#include <vector>

#include "geometry/solid.hpp"
#include "plan/deviation.hpp"
#include "plan/plan_file.hpp"
#include "plan/rejection.hpp"

namespace hybridctl::plan {

struct CandidateRun {
  // Why the plan does not make the part; none: it does (proven).
  std::vector<RejectionReason> reasons;
  // Actions executed: all of the plan's, or up to the one it stopped after.
  std::size_t executed = 0;
  // The material those actions left, on the plan's lattice; none when nothing ran (the
  // plan could not be written, or it begins as a plan already known to fail does).
  std::optional<geometry::Solid> as_built;
  // The design's core is missing after the last addition, which removals cannot put back.
  bool missing_after_last_addition = false;
  // A proven plan: each action's cycle time in minutes as `gcode check` estimates it from
  // the action's own program (0 for one that makes no G-code); empty otherwise.
  std::vector<double> action_minutes;
  // The part it makes against the design's real surface, when executed to its end (none:
  // the design has no real surface, as a design made on voxels, or the plan failed before).
  std::optional<ExactDeviation> exact;
  bool proven() const { return reasons.empty(); }
};

// Executes a candidate of `file` (its rank is 0: not an offered plan yet).
using CandidateExecutor = std::function<CandidateRun(const PlanFile& file, const PlanFilePlan& candidate)>;

}  // namespace hybridctl::plan
