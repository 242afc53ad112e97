#include "validation/plan_validator.hpp"

#include <algorithm>
#include <memory>
#include <utility>
#include <optional>

#include "common/error.hpp"
#include "common/number_text.hpp"
#include "gcode/check.hpp"
#include "gcode/post.hpp"

namespace hybridctl::validation {
namespace {

// Candidates beyond the tolerance against the STL before the rest are not verified.
constexpr int kExactFailuresBeforeGivingUp = 3;

// Minutes per action of an execution that ran to its end: each action's own program under
// the time model of `gcode check`.
std::vector<double> action_minutes(const Execution& run, const config::Machine& machine) {
  std::vector<double> minutes;
  for (const toolpaths::ExportedAction& a : run.exported.actions) {
    if (!a.makes_gcode) {
      minutes.push_back(0);
      continue;
    }
    const std::string text = gcode::write_action(a.program, machine);
    minutes.push_back(gcode::check_program(text, machine, a.primitive).time.total / 60.0);
  }
  return minutes;
}

}  // namespace

plan::CandidateExecutor plan_validator(const config::Machine& machine, ExecutionOptions options,
                                       std::shared_ptr<PrefixCache> cache) {
  struct State {
    ExecutionOptions options;
    // Execution is deterministic and an action depends only on the ones before it: a
    // candidate that begins with the actions a rejected one failed in fails the same way;
    // one that failed for the core missing after its last addition, so long as the
    // candidate only removes after them (Execution::missing_after_last_addition).
    struct FailedPrefix {
      std::vector<int> primitives;
      std::vector<plan::RejectionReason> reasons;
      bool only_if_removals_follow = false;
    };
    std::vector<FailedPrefix> failed_prefixes;
    // ... and the same holds for the prefixes that went right: candidates go on from there.
    std::shared_ptr<PrefixCache> cache;
    // Exact verification: candidates that made the part on the voxels but not against the
    // STL, and whether any made it against the STL. Its failures come from how faces are
    // cut and laid, which the search's next candidates mostly share; past a few, the rest
    // are turned down unexecuted rather than verified one by one.
    int exact_failures = 0;
    bool exact_passed = false;
    double closest_mm = 0;
  };
  // A candidate is rejected at its first failing action: its first reasons are enough.
  options.run_until = RunUntil::FirstFailingAction;
  auto state = std::make_shared<State>();
  state->options = std::move(options);
  state->cache = cache ? std::move(cache) : std::make_shared<PrefixCache>();
  return [&machine, state](const plan::PlanFile& file, const plan::PlanFilePlan& candidate) {
    const auto removes = [&](const plan::PlanFileAction& a) {
      return file.primitives.at(std::size_t(a.primitive)).mode == config::Mode::Subtractive;
    };
    for (const State::FailedPrefix& failed : state->failed_prefixes)
      if (failed.primitives.size() <= candidate.actions.size() &&
          std::equal(failed.primitives.begin(), failed.primitives.end(), candidate.actions.begin(),
                     [](int p, const plan::PlanFileAction& a) { return p == a.primitive; }) &&
          (!failed.only_if_removals_follow ||
           std::all_of(candidate.actions.begin() + std::ptrdiff_t(failed.primitives.size()), candidate.actions.end(), removes))) {
        plan::CandidateRun known;
        known.reasons = failed.reasons;
        return known;
      }
    if (!state->exact_passed && state->exact_failures >= kExactFailuresBeforeGivingUp) {
      plan::CandidateRun skipped;
      skipped.reasons = {{"not_verified", 0, 0,
                          "not executed: the " + std::to_string(state->exact_failures) +
                              " cheaper candidates that made the part on the voxels all left it beyond the tolerance "
                              "against the STL (the closest by " + fixed_number(state->closest_mm, 3) +
                              " mm): faces need finishing passes, or a looser tolerance (docs/verification.md)",
                          std::nullopt}};
      return skipped;
    }
    try {
      Execution run = execute_plan(file, candidate, machine, state->options, state->cache.get());
      if (run.exact) {
        if (run.exact->within_tolerance()) {
          state->exact_passed = true;
        } else if (run.proven() || std::all_of(run.reasons.begin(), run.reasons.end(), [](const plan::RejectionReason& r) {
                     return r.kind == "exact_excess" || r.kind == "exact_gouge";
                   })) {
          const double off = std::max(run.exact->excess.mm, run.exact->gouge.mm);
          state->closest_mm = state->exact_failures == 0 ? off : std::min(state->closest_mm, off);
          ++state->exact_failures;
        }
      }
      if (run.stopped_after > 0) {
        std::vector<int> prefix;
        for (int k = 0; k < run.stopped_after; ++k) prefix.push_back(candidate.actions[std::size_t(k)].primitive);
        state->failed_prefixes.push_back({std::move(prefix), run.reasons, run.missing_after_last_addition});
      }
      plan::CandidateRun out;
      if (run.proven()) {
        if (run.exported.actions.size() == candidate.actions.size()) out.action_minutes = action_minutes(run, machine);
        out.exact = run.exact;
        return out;
      }
      out.executed = run.stopped_after > 0 ? std::size_t(run.stopped_after) : candidate.actions.size();
      out.missing_after_last_addition = run.missing_after_last_addition;
      out.as_built = std::move(run.as_built);
      out.reasons = std::move(run.reasons);
      return out;
    } catch (const InputError& e) {
      // The plan cannot be written for this machine (a move beyond its envelope, ...): it
      // makes no part, and the search goes on.
      plan::CandidateRun unwritable;
      unwritable.reasons = {{"not_exportable", 0, 0, e.what(), std::nullopt}};
      return unwritable;
    }
  };
}

}  // namespace hybridctl::validation
