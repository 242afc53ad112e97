#pragma once
// What executing a candidate plan from the raw stock showed (validation/,
// docs/validation.md): the contract between validation, which runs the plan's G-code on
// the simulated machine, and the planner, which learns from it what its primitives do not
// do (planner/pipeline/shortfall.hpp). In plan.json's terms, so that neither needs the other.

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "geometry/mesh.hpp"
#include "geometry/solid.hpp"
#include "plan/deviation.hpp"
#include "plan/plan_file.hpp"
#include "plan/rejection.hpp"
#include "plan/unreached_corner.hpp"

namespace hybridctl::plan {

// A program's cycle time under `gcode check`'s model (docs/gcode.md, "The time model"):
// its seconds, and the text that says what they include.
struct CycleTime {
  double seconds = 0;
  std::string text;
};

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
  // A proven plan: each action's minutes of motion and dwell in its own program under
  // `gcode check`'s model (0 for one that makes no G-code; the changes are the plan's);
  // empty otherwise.
  std::vector<double> action_minutes;
  // A proven plan: its whole program's cycle time, changes included.
  std::optional<CycleTime> cycle_time;
  // The part it makes against the design's real surface, when executed to its end (none:
  // the design has no real surface, as a design made on voxels, or the plan failed before).
  std::optional<ExactDeviation> exact;
  bool proven() const { return reasons.empty(); }
};

// Executes a candidate of `file` (its rank is 0: not an offered plan yet).
using CandidateExecutor = std::function<CandidateRun(const PlanFile& file, const PlanFilePlan& candidate)>;

// The reasons the executor would turn a candidate down for without executing it (it
// repeats what candidates executed before showed); none: it would be executed.
using KnownRejection =
    std::function<std::optional<std::vector<RejectionReason>>(const PlanFile& file, const PlanFilePlan& candidate)>;

// The stretches of the design's vertical inside edges no cutter of the machine comes
// within `reach` (mm) of, at least `min_stretch` mm long (toolpaths/corner_reach.hpp).
using CornerFinder =
    std::function<std::vector<UnreachedCorner>(const geometry::TriangleMesh& design, double reach, double min_stretch)>;

// An executor and what it already knows, asked first so that a candidate known to fail is
// passed over without being executed or counted as a rejection; and what the machine's
// cutters cannot reach, asked before the search (none: not asked).
struct CandidateValidator {
  CandidateExecutor execute;
  KnownRejection known;
  CornerFinder corners;
};

}  // namespace hybridctl::plan
