#pragma once
// Plans built without search, the way a person plans by hand: start somewhere, deposit what
// the design still lacks, then mill what lies outside it. The exact search proves plans
// cheapest first and stops at its limits on large problems, and weighted A* follows its
// bound, which on a machine with many tools prefers a start that is cheap to finish over a
// raw stock that is cheap to make (a block milled to the part, docs/search.md): these plans
// are offered beside the weighted ones, each with its proven gap, so that a problem the
// search cannot finish still gets the plan a shop would try first.

#include <cstddef>
#include <vector>

#include "planner/search/search.hpp"

namespace hybridctl::planner {

// Sequences of primitive indices that reach the goal in `problem`, cheapest first, at most
// `limit`, distinct. From every primitive a plan may start with: while a must-in atom is
// missing, the deposit that lays the most of the missing design per unit of cost without
// laying material outside it that no removal sparing the design clears; then the removal
// sparing the design present that clears the most of what lies outside it per unit of
// cost. Each plan found is varied by leaving out one of its actions in turn (the runner-up
// choices), which gives the next plans.
std::vector<std::vector<int>> greedy_sequences(const PlanningProblem& problem, std::size_t limit);

}  // namespace hybridctl::planner
