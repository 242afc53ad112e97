#pragma once
// What the plan search can tell before and while it searches, from the goal backwards
// (docs/search.md): which primitives can take part in a plan at all, and the problem
// reduced to them, with atoms every one of them treats alike merged into one.

#include <cstdint>
#include <vector>

#include "planner/search/search.hpp"

namespace hybridctl::planner {

// Read backwards, a plan's last action decides the final status of every atom it holds:
// it may hold no atom its mode gets wrong (an additive one no must-out atom, a subtractive
// one no must-in atom). The action before it may hold such atoms only where a later one
// decides them, and so on. Placing every primitive whose wrong atoms all lie in those
// placed, until no more can be, gives every primitive that some plan's suffix can hold:
// the others can take no part in reaching the goal. Costs, order and reach aside, so the
// set only ever holds too many.
class SuffixClosure {
 public:
  explicit SuffixClosure(const PlanningProblem& problem);

  // Those of `candidates` some suffix of a plan reaching the goal can hold.
  std::vector<bool> usable(std::vector<bool> candidates) const;
  // The atoms they hold: a state's wrong atoms outside it no completion fixes.
  std::vector<std::uint64_t> decided(const std::vector<bool>& usable) const;

 private:
  const PlanningProblem& p_;
  std::vector<std::vector<std::uint64_t>> wrong_;  // per primitive: atoms its mode gets wrong
};

// The problem the search runs on: the primitives that can take part in a plan, and the
// atoms they hold, merged where every one of them holds all or none of a group (volumes
// add, classes unite; their reach and footing remapped, and atoms whose footing differs
// kept apart). The same plans, step for step, at the same costs.
struct Reduction {
  PlanningProblem problem;
  std::vector<int> primitive;  // reduced primitive -> original
  std::vector<int> atom;       // original atom -> reduced atom; -1: no primitive holds it
  int original_atoms = 0;
  bool infeasible = false;     // no plan can reach the goal
};
Reduction reduce(const PlanningProblem& problem);

// A plan of the reduced problem in the original's terms.
Plan lift(const Reduction& reduction, const Plan& plan);

}  // namespace hybridctl::planner
