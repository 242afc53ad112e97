#include "planner/pipeline/rank.hpp"

#include <numeric>

#include "planner/costing/toolpath_rank.hpp"

namespace hybridctl::planner {

void rank_by_toolpaths(const config::Machine& machine, PlanningResult& r) {
  const ToolpathRanking ranking = rank_by_toolpaths(machine, r.primitives, r.objective, r.plans, r.toolpath_minutes);
  r.estimates_off = ranking.estimates_off;
  r.search_rank.resize(r.plans.size());
  std::iota(r.search_rank.begin(), r.search_rank.end(), 0);
  r.ranked_by_toolpaths = ranking.ranked;
  if (!ranking.ranked) return;
  r.toolpath_costs = ranking.costs;
  const std::vector<std::size_t>& order = ranking.order;
  const auto permute = [&order](auto& v) {
    if (v.size() != order.size()) return;
    auto copy = v;
    for (std::size_t i = 0; i < order.size(); ++i) v[i] = std::move(copy[order[i]]);
  };
  permute(r.plans);
  permute(r.deviations);
  permute(r.exact_deviations);
  permute(r.estimates);
  permute(r.toolpath_minutes);
  permute(r.cycle_times);
  permute(r.search_rank);
  permute(r.toolpath_costs);
}

double cost_with_toolpaths(const config::Machine& machine, const PlanningResult& r, const Plan& plan,
                           const std::vector<double>& toolpath) {
  return cost_with_toolpaths(machine, r.primitives, r.objective, plan, toolpath);
}

}  // namespace hybridctl::planner
