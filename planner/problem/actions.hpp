#pragma once
// The rules of plans on the symbolic problem (planner/problem/problem.hpp): what an action
// does to a state, what changing between actions costs, when a plan has reached the goal,
// and a plan as the paper writes it. The one definition the search, the proofs, the plans'
// regions of influence and the learning from executed candidates share.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "planner/problem/problem.hpp"

namespace hybridctl::planner {

// What primitive `i` does to `state` as an action of a plan: `next` is the state after it
// and `changed` (words, as AtomSet's) the atoms it deposits (additive: those absent) or
// removes (subtractive: those present), less what execution showed it falls short on
// (PrimitiveSpec::falls_short) once the plan has begun. `first`: the plan's first action,
// which works on the plate, where what failed later is not in its way.
void action_effect(const PlanningProblem& p, const AtomSet& state, int i, bool first, AtomSet& next,
                   std::vector<std::uint64_t>& changed);

// A plan replayed on atom sets with action_effect, step by step: the state after its first
// `steps` actions (all of them by default), per atom the step that changed it last (-1:
// none), and per step the atoms it changed (words, as AtomSet's).
struct PlanReplay {
  AtomSet state;
  std::vector<int> last;
  std::vector<std::vector<std::uint64_t>> changed;
};
PlanReplay replay_plan(const PlanningProblem& p, const Plan& plan, std::size_t steps = SIZE_MAX);

// The state after applying primitive `i`, and the volume it really changes; false when
// it changes nothing or cannot be taken in this state (a deposit out of the head's reach,
// or with nothing to carry its first layer). `first`: the plan's first action (on the plate).
bool apply(const PlanningProblem& p, const AtomSet& state, int i, AtomSet& next, double& volume, bool first);

// The fixed costs of `next` after `previous` (-1: `next` starts the plan), not normalised;
// none after a raw stock, which is clamped in the setup `next` takes.
double fixed_cost(const PlanningProblem& p, int previous, int next);

// The plan that takes these steps from the empty state, with each step's volume and cost;
// false when a step cannot be taken or changes nothing, or comes after the goal is reached
// (a plan ends there).
bool simulate(const PlanningProblem& p, const std::vector<int>& sequence, Plan& plan);

// True when every must-in atom is in `state` and no must-out atom is.
bool is_goal(const PlanningProblem& problem, const AtomSet& state);

// The plan as the paper writes it, e.g. "(((P1 ∪ P2) − P3) − P4)".
std::string expression(const PlanningProblem& problem, const Plan& plan);

}  // namespace hybridctl::planner
