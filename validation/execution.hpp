#pragma once
// A plan proven by execution (docs/validation.md): its actions are turned into toolpaths
// one after the other, each planned against the material really present after the ones
// before it, and the whole plan's program, as export writes it, is executed on the
// simulated machine (sim::ProgramExecutor: interpreter, envelope, interlocks, material)
// from the raw stock through every action in order. What comes out is the program, the
// part as built, what went wrong on the way, and the located reasons why the plan does
// not make the part, if any.
//
//   const validation::Execution run = validation::execute_plan(file, file.plans[0], machine);
//   if (!run.proven()) for (const auto& r : run.reasons) ... plan::describe(r) ...
//
// This library sits above toolpaths and sim and knows plans only as plan files
// (docs/architecture.md); the planner offers it candidates through a plan::CandidateExecutor
// (validation/plan_validator.hpp, planner/pipeline/candidate_execution.hpp).

#include <string>
#include <vector>

#include "common/error.hpp"
#include "config/machine.hpp"
#include "gcode/program.hpp"
#include "geometry/solid.hpp"
#include "plan/deviation.hpp"
#include "plan/plan_file.hpp"
#include "plan/rejection.hpp"
#include "sim/material.hpp"
#include "toolpaths/plan_export.hpp"
#include "validation/prefix_cache.hpp"
#include "verification/exact_deviation.hpp"

namespace hybridctl::validation {

// A plan that does not make its part: executing it found located reasons. Nothing is
// written or streamed; the CLI maps it to exit code 4, as for a part that is not
// manufacturable.
class NotManufacturableError : public InputError {
 public:
  using InputError::InputError;
};

// What each action's toolpath is planned against.
enum class PlannedAgainst {
  MaterialPresent,  // the stock the simulation holds after the actions before it (export, run, plan)
  PlannedState,     // the plan's planned state (the export before validation; for comparison)
};

// How far a plan is executed once something goes wrong.
enum class RunUntil {
  End,                 // every action: every reason (export, run, dry-run)
  FirstFailingAction,  // the end of the first action with a path defect, an incident or a refused line: enough to
                       // reject a candidate (plan's validation), and much cheaper
};

struct ExecutionOptions {
  toolpaths::ExportOptions export_options;  // generators and post-processor (dialect, name)
  sim::SimulationOptions simulation;
  PlannedAgainst planned_against = PlannedAgainst::MaterialPresent;
  RunUntil run_until = RunUntil::End;
  // The design's real surface for exact verification; null: the STL the plan file names,
  // read when a plan passes on the voxels.
  std::shared_ptr<verification::DesignSurfaces> surfaces;
  // Off: the voxels alone (bench/exact_verification_bench compares the two).
  bool verify_exactly = true;
};

struct Execution {
  toolpaths::PlanExport exported;      // toolpaths planned against the material present (when stopped early:
                                       // the actions made, without their solids; resumed from a
                                       // PrefixCache: the prefix's actions without their solids)
  gcode::PostedProgram program;        // the whole plan's program, as export writes it
  geometry::Solid as_built;            // part frame, the plan's lattice and domain
  sim::SimulationReport report;        // incidents carry the program's lines
  std::vector<std::string> errors;     // lines the machine refused (G-code, envelope, interlocks)
  plan::Deviation deviation;        // as built against the design, on the voxels
  // The part made against the design's real surface (verification/): for a plan that
  // passes on the voxels and ran to its end, when the plan file has a real surface.
  std::optional<plan::ExactDeviation> exact;
  std::vector<plan::RejectionReason> reasons;  // empty: the plan makes the part
  int stopped_after = 0;  // RunUntil::FirstFailingAction: the action it stopped after (0: ran to the end)
  // Stopped after the plan's last action that adds material, with part of the design's
  // core (the design shrunk by the tolerance) missing: removals alone cannot put it back,
  // so any plan that begins with these actions and only removes after them fails alike.
  bool missing_after_last_addition = false;
  bool proven() const { return reasons.empty(); }
};

// Exports and executes `plan` of `file` on `machine` from its raw stock (an empty stock on
// the plan's domain when it starts with deposition). Each action's lines spare what the
// action keeps of the design, shrunk by the tolerance (plan::spared_by_cuts; a cut into
// it is a gouge): a removal's own region may take design material a later deposit builds
// again, and the deviation judges the part as built. Throws
// InputError when an action cannot be written for the machine (another machine, an
// instrument it lacks, a move beyond its envelope), as toolpaths::export_plan and
// gcode::post_program do.
Execution execute_plan(const plan::PlanFile& file, const plan::PlanFilePlan& plan, const config::Machine& machine,
                       const ExecutionOptions& options = {});

// execute_plan resumed from the longest prefix of `plan` that `cache` holds, keeping the
// state after each action that goes right in it (validation/prefix_cache.hpp): the same
// Execution as from the raw stock (reasons, lines, program, as built, report), but for the
// solids of the resumed actions in `exported`. `cache` serves one file, machine and
// options; null, or PlannedAgainst::PlannedState, executes from the raw stock.
Execution execute_plan(const plan::PlanFile& file, const plan::PlanFilePlan& plan, const config::Machine& machine,
                       const ExecutionOptions& options, PrefixCache* cache);

// The reasons of an execution, as execute_plan fills `reasons`: the toolpaths' defects
// (layer skipped, region unreachable), every incident kind per action (rapid into
// material, body collision, gouge, unsupported deposit, ...), refused lines, and the part
// as built outside the tolerance (missing or excess material). A plan that passes all of
// these is verified exactly against the design's real surface (Execution::exact): beyond
// the tolerance either way adds an "exact_excess" or "exact_gouge" reason with its place.
std::vector<plan::RejectionReason> rejection_reasons(const Execution& execution, const plan::PlanFile& file,
                                                        const config::Machine& machine);

// plan.json's name for an incident kind ("rapid_into_material", "body_collision", ...).
std::string reason_kind(sim::IncidentKind kind);

// The reasons as lines for people, at most `shown` of them and a count of the rest.
std::string describe_reasons(const std::vector<plan::RejectionReason>& reasons, std::size_t shown = 20);

// execute_plan, and a NotManufacturableError (exit 4) naming `what` ("plan 2 (expr)") and
// every reason when there is any (the plan does not make its part, or is unsafe to run):
// export and run write or stream nothing then.
Execution require_proven(const plan::PlanFile& file, const plan::PlanFilePlan& plan,
                         const config::Machine& machine, const ExecutionOptions& options, const std::string& what);

}  // namespace hybridctl::validation
