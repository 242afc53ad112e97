#include "planner/toolpath_rank.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace hybridctl::planner {
namespace {

// Money per minute of an action's work beyond its material: the machine's time and a
// tool's wear.
double money_per_minute(const config::Machine& m, const Primitive& p) {
  double rate = m.costs.machine_rate / 60.0;
  if (p.mode == Mode::Subtractive && p.tool_number > 0)
    if (const config::CuttingTool* t = m.find_tool(p.tool_number)) rate += t->tool_price / t->tool_life;
  return rate;
}

}  // namespace

bool estimate_off(double estimated, double toolpath) {
  if (std::max(estimated, toolpath) < 1.0) return false;
  return std::abs(toolpath - estimated) > kEstimateTolerance * std::max(estimated, 1e-9);
}

double estimated_work(const config::Machine& machine, const PlanningResult& r, const PlanStep& step) {
  return per_mm3(machine, r.primitives[std::size_t(step.primitive)]).minutes * step.volume;
}

double cost_with_toolpaths(const config::Machine& machine, const PlanningResult& r, const Plan& plan,
                           const std::vector<double>& toolpath) {
  double cost = 0;
  for (std::size_t s = 0; s < plan.steps.size(); ++s) {
    const PlanStep& step = plan.steps[s];
    const Primitive& p = r.primitives[std::size_t(step.primitive)];
    const double estimated = estimated_work(machine, r, step);
    const double actual = s < toolpath.size() ? toolpath[s] : estimated;
    switch (r.objective) {
      case config::Objective::Time: cost += step.cost + (actual - estimated); break;
      case config::Objective::Money: cost += step.cost + (actual - estimated) * money_per_minute(machine, p); break;
      case config::Objective::CostFactor: cost += step.cost; break;  // not a time
    }
  }
  return cost;
}

void rank_by_toolpaths(const config::Machine& machine, PlanningResult& r) {
  r.estimates_off = 0;
  for (std::size_t k = 0; k < r.plans.size() && k < r.toolpath_minutes.size(); ++k)
    for (std::size_t s = 0; s < r.plans[k].steps.size() && s < r.toolpath_minutes[k].size(); ++s)
      r.estimates_off += estimate_off(estimated_work(machine, r, r.plans[k].steps[s]), r.toolpath_minutes[k][s]);
  const bool off = r.estimates_off > 0;
  std::vector<std::size_t> order(r.plans.size());
  std::iota(order.begin(), order.end(), 0);
  r.search_rank = order;
  // Cost factors are not times: their ranking stands, the toolpaths' times are only shown.
  r.ranked_by_toolpaths = off && r.toolpath_minutes.size() == r.plans.size() && r.objective != config::Objective::CostFactor;
  if (!r.ranked_by_toolpaths) return;
  std::vector<double> cost;
  for (std::size_t k = 0; k < r.plans.size(); ++k)
    cost.push_back(cost_with_toolpaths(machine, r, r.plans[k], r.toolpath_minutes[k]));
  r.toolpath_costs = cost;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return cost[a] < cost[b]; });
  const auto permute = [&order](auto& v) {
    if (v.size() != order.size()) return;
    auto copy = v;
    for (std::size_t i = 0; i < order.size(); ++i) v[i] = std::move(copy[order[i]]);
  };
  permute(r.plans);
  permute(r.deviations);
  permute(r.estimates);
  permute(r.toolpath_minutes);
  permute(r.search_rank);
  permute(r.toolpath_costs);
}

}  // namespace hybridctl::planner
