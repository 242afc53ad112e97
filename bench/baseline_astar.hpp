#pragma once
// The A* plan search before issue 15, for planner_bench's baseline (baseline_astar.cpp).

#include "planner/search/search.hpp"

namespace hybridctl::planner::baseline {

std::vector<Plan> find_plans(const PlanningProblem& problem, const SearchOptions& options, SearchStats* stats);

}  // namespace hybridctl::planner::baseline
