#include "validation/plan_validator.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <utility>
#include <optional>
#include <set>

#include "common/error.hpp"
#include "common/number_text.hpp"
#include "gcode/check.hpp"
#include "gcode/post.hpp"
#include "toolpaths/corner_reach.hpp"

namespace hybridctl::validation {
namespace {

// Candidates beyond the tolerance against the STL before the rest are not verified.
constexpr int kExactFailuresBeforeGivingUp = 3;

// Where a candidate left the part beyond the tolerance against the STL: its actions up to
// the one that left that surface (their primitives), and the place.
struct ExactFailure {
  std::vector<int> prefix;
  bool excess = true;  // material out of the surface (else a gouge)
  geometry::Vec3 at;
  double mm = 0;
  // An excess where nothing deposits: the candidate's first action (its stock) and the
  // removals whose regions reach the place; empty when a deposit reaches it.
  std::vector<int> cutters;
  int stock = -1;
};

// Whether `region` holds a voxel next to the one at `at` (26-neighbourhood, itself included).
bool reaches(const geometry::Solid& region, geometry::Vec3 at) {
  const geometry::Lattice& l = region.lattice();
  const geometry::Index3 c{int(std::floor((at.x - l.origin.x) / l.voxel_size)), int(std::floor((at.y - l.origin.y) / l.voxel_size)),
                           int(std::floor((at.z - l.origin.z) / l.voxel_size))};
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx)
        if (region.contains({c.x + dx, c.y + dy, c.z + dz})) return true;
  return false;
}

// The candidate leaves the same surface as `f` did: it begins with f's actions (execution
// is deterministic: the same material there after them), and nothing after them could
// change that place (no removal reaches an excess, no deposit a gouge).
bool repeats(const ExactFailure& f, const plan::PlanFile& file, const plan::PlanFilePlan& candidate) {
  const auto& actions = candidate.actions;
  // An excess where only removals reach: what stays there is the stock less what they
  // sweep, so a candidate from the same stock whose removals reaching it are among the
  // failed one's leaves at least as much (up to toolpaths that differ with the material
  // they meet: a judgement, not a proof, which spares executing the same tools' failure on
  // a face again in every order).
  if (f.excess && f.stock >= 0 && !actions.empty() && actions.front().primitive == f.stock) {
    bool among = true;
    for (std::size_t i = 1; i < actions.size() && among; ++i) {
      const plan::PlanFilePrimitive& p = file.primitives.at(std::size_t(actions[i].primitive));
      if (!reaches(p.region, f.at)) continue;
      among = p.mode == config::Mode::Subtractive &&
              std::find(f.cutters.begin(), f.cutters.end(), actions[i].primitive) != f.cutters.end();
    }
    if (among) return true;
  }
  if (actions.size() < f.prefix.size() ||
      !std::equal(f.prefix.begin(), f.prefix.end(), actions.begin(),
                  [](int p, const plan::PlanFileAction& a) { return p == a.primitive; }))
    return false;
  return std::none_of(actions.begin() + std::ptrdiff_t(f.prefix.size()), actions.end(), [&](const plan::PlanFileAction& a) {
    const plan::PlanFilePrimitive& p = file.primitives.at(std::size_t(a.primitive));
    return (p.mode == config::Mode::Subtractive) == f.excess && reaches(p.region, f.at);
  });
}

// Where `candidate` left the part beyond the tolerance against the STL (`exact`), as the
// skip rule above keeps it; nothing when the place is not known.
std::optional<ExactFailure> failure_of(const plan::PlanFile& file, const plan::PlanFilePlan& candidate,
                                       const plan::ExactDeviation& exact) {
  const bool excess = exact.excess.mm >= exact.gouge.mm;
  const plan::ExactPlace& place = excess ? exact.excess : exact.gouge;
  if (!place.at || place.action < 1 || std::size_t(place.action) > candidate.actions.size()) return std::nullopt;
  ExactFailure f{{}, excess, *place.at, place.mm, {}, -1};
  for (int k = 0; k < place.action; ++k) f.prefix.push_back(candidate.actions[std::size_t(k)].primitive);
  bool deposited = false;
  for (std::size_t k = 1; k < candidate.actions.size(); ++k) {
    const plan::PlanFilePrimitive& p = file.primitives.at(std::size_t(candidate.actions[k].primitive));
    if (!reaches(p.region, f.at)) continue;
    if (p.mode == config::Mode::Subtractive)
      f.cutters.push_back(candidate.actions[k].primitive);
    else
      deposited = true;
  }
  if (excess && !deposited && !candidate.actions.empty()) f.stock = candidate.actions.front().primitive;
  return f;
}

// The rejection of a candidate that repeats `f`, unexecuted.
plan::CandidateRun repeated(const ExactFailure& f) {
  plan::CandidateRun known;
  known.reasons = {{f.excess ? "exact_excess" : "exact_gouge", 0, 0,
                    "not executed: a candidate executed before left the part " + fixed_number(f.mm, 3) + " mm " +
                        (f.excess ? "out of" : "inside") + " the design's surface at (" + fixed_number(f.at.x, 2) + ", " +
                        fixed_number(f.at.y, 2) + ", " + fixed_number(f.at.z, 2) +
                        ") mm, and this one reaches that place with none but the same actions",
                    f.at}};
  return known;
}

// Minutes per action of an execution that ran to its end: the motion and dwell of each
// action's own program under the time model of `gcode check` (its changes are the plan's).
std::vector<double> action_minutes(const Execution& run, const config::Machine& machine) {
  std::vector<double> minutes;
  for (const toolpaths::ExportedAction& a : run.exported.actions) {
    if (!a.makes_gcode) {
      minutes.push_back(0);
      continue;
    }
    const std::string text = gcode::write_action(a.program, machine);
    const gcode::TimeEstimate time = gcode::check_program(text, machine, a.primitive).time;
    minutes.push_back((time.motion + time.dwell) / 60.0);
  }
  return minutes;
}

// The inside corners no cutter of `machine` reaches (toolpaths/corner_reach.hpp), on the
// design's own triangles.
plan::CornerFinder corner_finder(const config::Machine& machine) {
  return [&machine](const geometry::TriangleMesh& design, double reach, double min_stretch) {
    toolpaths::CornerReachOptions o;
    o.reach = reach;
    o.min_stretch = min_stretch;
    return toolpaths::corners_no_cutter_reaches(geometry::clean_mesh(design).triangles, machine, o);
  };
}

}  // namespace

plan::CandidateValidator plan_validator(const config::Machine& machine, ExecutionOptions options,
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
    // cut and laid: a candidate that runs the action which left a face out and nothing
    // after it that reaches that place leaves it the same, and is turned down unexecuted;
    // past a few failures, every other one is too.
    std::vector<ExactFailure> exact_failed;
    int exact_failures = 0;
    std::set<int> tried;  // the primitives of the candidates those failures came from
    bool exact_passed = false;
    double closest_mm = 0;
  };
  // A candidate is rejected at its first failing action: its first reasons are enough.
  options.run_until = RunUntil::FirstFailingAction;
  auto state = std::make_shared<State>();
  state->options = std::move(options);
  state->cache = cache ? std::move(cache) : std::make_shared<PrefixCache>();
  // The reasons a candidate is turned down for unexecuted, if any.
  auto known = [state](const plan::PlanFile& file,
                       const plan::PlanFilePlan& candidate) -> std::optional<std::vector<plan::RejectionReason>> {
    const auto removes = [&](const plan::PlanFileAction& a) {
      return file.primitives.at(std::size_t(a.primitive)).mode == config::Mode::Subtractive;
    };
    for (const State::FailedPrefix& failed : state->failed_prefixes)
      if (failed.primitives.size() <= candidate.actions.size() &&
          std::equal(failed.primitives.begin(), failed.primitives.end(), candidate.actions.begin(),
                     [](int p, const plan::PlanFileAction& a) { return p == a.primitive; }) &&
          (!failed.only_if_removals_follow ||
           std::all_of(candidate.actions.begin() + std::ptrdiff_t(failed.primitives.size()), candidate.actions.end(), removes)))
        return failed.reasons;
    for (const ExactFailure& f : state->exact_failed)
      if (repeats(f, file, candidate)) return repeated(f).reasons;
    return std::nullopt;
  };
  auto execute = [&machine, state, known](const plan::PlanFile& file, const plan::PlanFilePlan& candidate) {
    plan::CandidateRun unexecuted;
    if (std::optional<std::vector<plan::RejectionReason>> reasons = known(file, candidate)) {
      unexecuted.reasons = std::move(*reasons);
      return unexecuted;
    }
    // Past a few failures against the STL and none passing, a candidate is executed only
    // when it brings a primitive none of them had (another tool, another setup): one
    // judged, not known, to fail, so it counts as a rejection.
    const bool tried = std::all_of(candidate.actions.begin(), candidate.actions.end(),
                                   [&](const plan::PlanFileAction& a) { return state->tried.count(a.primitive) > 0; });
    if (!state->exact_passed && state->exact_failures >= kExactFailuresBeforeGivingUp && tried) {
      unexecuted.reasons = {{"not_verified", 0, 0,
                             "not executed: the " + std::to_string(state->exact_failures) +
                                 " cheaper candidates that made the part on the voxels all left it beyond the "
                                 "tolerance against the STL (the closest by " + fixed_number(state->closest_mm, 3) +
                                 " mm), and this one has no primitive they did not: faces need finishing passes, or "
                                 "a looser tolerance (docs/verification.md)",
                             std::nullopt}};
      return unexecuted;
    }
    try {
      Execution run = execute_plan(file, candidate, machine, state->options, state->cache.get());
      if (run.exact) {
        if (run.exact->within_tolerance()) {
          state->exact_passed = true;
        } else if (run.proven() || std::all_of(run.reasons.begin(), run.reasons.end(), [](const plan::RejectionReason& r) {
                     return r.kind == "exact_excess" || r.kind == "exact_gouge";
                   })) {
          // A face left as deposited is the deposit's, which the planner learns and passes
          // over from then on (planner/pipeline/deposited_faces.hpp); a machined face beyond
          // the tolerance says the finishing falls short, which every later candidate shares.
          const plan::ExactPlace& worst = run.exact->excess.mm >= run.exact->gouge.mm ? run.exact->excess : run.exact->gouge;
          if (!worst.as_deposited) {
            const double off = std::max(run.exact->excess.mm, run.exact->gouge.mm);
            state->closest_mm = state->exact_failures == 0 ? off : std::min(state->closest_mm, off);
            ++state->exact_failures;
            for (const plan::PlanFileAction& a : candidate.actions) state->tried.insert(a.primitive);
          }
          if (std::optional<ExactFailure> f = failure_of(file, candidate, *run.exact)) state->exact_failed.push_back(*f);
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
        const gcode::TimeEstimate time = gcode::check_program(run.program.text(), machine, "plan").time;
        out.cycle_time = plan::CycleTime{time.total, time.str()};
        out.exact = run.exact;
        return out;
      }
      out.executed = run.stopped_after > 0 ? std::size_t(run.stopped_after) : candidate.actions.size();
      out.missing_after_last_addition = run.missing_after_last_addition;
      out.as_built = std::move(run.as_built);
      out.reasons = std::move(run.reasons);
      out.exact = std::move(run.exact);
      return out;
    } catch (const InputError& e) {
      // The plan cannot be written for this machine (a move beyond its envelope, ...): it
      // makes no part, and the search goes on.
      plan::CandidateRun unwritable;
      unwritable.reasons = {{"not_exportable", 0, 0, e.what(), std::nullopt}};
      return unwritable;
    }
  };
  return {execute, known, corner_finder(machine)};
}

}  // namespace hybridctl::validation
