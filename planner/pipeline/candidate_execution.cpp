#include "planner/pipeline/candidate_execution.hpp"

#include <map>
#include <memory>
#include <optional>
#include <utility>

#include "plan/start_stock.hpp"
#include "planner/pipeline/plan_report.hpp"

namespace hybridctl::planner {

plan::PlanFilePlan candidate_plan(const PlanningResult& r, const Plan& plan) {
  plan::PlanFilePlan out{0, expression(r.problem, plan), plan.cost, {}};
  for (const PlanStep& step : plan.steps) out.actions.push_back({step.primitive, step.volume, step.cost});
  return out;
}

CandidateCheck learn_from_run(const PlanningResult& r, const Plan& plan, const plan::PlanFile& file, plan::CandidateRun run,
                              std::optional<geometry::Solid>& core) {
  if (run.proven()) return CandidateCheck{};
  // Faces left beyond the tolerance as deposited: the deposit's own, wherever the plan stands.
  std::vector<DepositedFace> faces;
  if (run.exact)
    for (const plan::ExactPlace* place : {&run.exact->excess, &run.exact->gouge})
      if (place->as_deposited && place->at && place->mm > run.exact->tolerance && place->action >= 1 &&
          std::size_t(place->action) <= plan.steps.size())
        faces.push_back({plan.steps[std::size_t(place->action - 1)].primitive, *place->at, place->mm,
                         place == &run.exact->excess});
  if (!run.as_built) {
    CandidateCheck check{std::move(run.reasons)};
    check.faces = std::move(faces);
    return check;
  }
  const geometry::Solid& built = *run.as_built;
  const std::size_t executed = run.executed;
  std::vector<Shortfall> shortfalls = find_shortfalls(r.problem, r.atoms, plan, executed, built);
  if (shortfalls.empty() && run.missing_after_last_addition) {
    if (!core) core = plan::spared_by_cuts(file);
    shortfalls = find_missing_core_shortfalls(r.problem, r.atoms, plan, executed, geometry::subtract(*core, built));
  }
  if (shortfalls.empty()) shortfalls = find_skipped_layer_shortfalls(r.problem, r.atoms, plan, executed, built, run.reasons);
  if (shortfalls.empty())
    shortfalls = spills_beyond_the_grid(find_spills(r.problem, r.atoms, plan, executed, built, run.reasons),
                                        r.atoms, r.measures, run.exact);
  CandidateCheck check{std::move(run.reasons), std::move(shortfalls)};
  check.faces = std::move(faces);
  return check;
}

void validate_by_execution(PlanningOptions& options, plan::CandidateValidator validator, const std::string& machine_name) {
  struct State {
    plan::CandidateValidator validator;
    std::string machine_name;
    std::optional<plan::PlanFile> file;    // the planning result's grid, design and primitives
    std::optional<geometry::Solid> core;   // the design's core (plan::spared_by_cuts), once
    // Per proven candidate (its primitives in order): what its run measured.
    struct Proven {
      std::vector<double> action_minutes;
      std::optional<plan::CycleTime> cycle_time;
      std::optional<plan::ExactDeviation> exact;
    };
    std::map<std::vector<int>, Proven> proven;
    const Proven* proven_of(const Plan& plan) const {
      const auto it = proven.find(plan.primitives());
      return it == proven.end() ? nullptr : &it->second;
    }
  };
  auto state = std::make_shared<State>();
  state->validator = std::move(validator);
  state->machine_name = machine_name;
  const auto file_of = [state](const PlanningResult& r) -> const plan::PlanFile& {
    if (!state->file) {
      // No plans yet: only the grid, the design and the primitives are taken.
      const ReportSources sources{"", "", state->machine_name, ""};
      state->file = to_plan_file(r, sources, ".");
    }
    return *state->file;
  };
  if (state->validator.known)
    options.known_failure = [state, file_of](const PlanningResult& r, const Plan& plan) {
      return state->validator.known(file_of(r), candidate_plan(r, plan)).has_value();
    };
  options.validate = [state, file_of](const PlanningResult& r, const Plan& plan) {
    const plan::PlanFile& file = file_of(r);
    plan::CandidateRun run = state->validator.execute(file, candidate_plan(r, plan));
    if (run.proven()) {
      state->proven[plan.primitives()] = {run.action_minutes, run.cycle_time, run.exact};
    }
    return learn_from_run(r, plan, *state->file, std::move(run), state->core);
  };
  options.corners = state->validator.corners;
  options.toolpath_minutes = [state](const Plan& plan) {
    const State::Proven* p = state->proven_of(plan);
    return p ? p->action_minutes : std::vector<double>{};
  };
  options.cycle_time = [state](const Plan& plan) {
    const State::Proven* p = state->proven_of(plan);
    return p ? p->cycle_time : std::nullopt;
  };
  options.exact_deviation = [state](const Plan& plan) {
    const State::Proven* p = state->proven_of(plan);
    return p ? p->exact : std::nullopt;
  };
}

}  // namespace hybridctl::planner
