#include "planner/costing/toolpath_rank.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "planner/costing/costs.hpp"

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

double estimated_work(const config::Machine& machine, const std::vector<Primitive>& primitives, const PlanStep& step) {
  return per_mm3(machine, primitives[std::size_t(step.primitive)]).minutes * step.volume;
}

double cost_with_toolpaths(const config::Machine& machine, const std::vector<Primitive>& primitives,
                           config::Objective objective, const Plan& plan, const std::vector<double>& toolpath) {
  double cost = 0;
  for (std::size_t s = 0; s < plan.steps.size(); ++s) {
    const PlanStep& step = plan.steps[s];
    const Primitive& p = primitives[std::size_t(step.primitive)];
    const double estimated = estimated_work(machine, primitives, step);
    const double actual = s < toolpath.size() ? toolpath[s] : estimated;
    switch (objective) {
      case config::Objective::Time: cost += step.cost + (actual - estimated); break;
      case config::Objective::Money: cost += step.cost + (actual - estimated) * money_per_minute(machine, p); break;
      case config::Objective::CostFactor: cost += step.cost; break;  // not a time
    }
  }
  return cost;
}

ToolpathRanking rank_by_toolpaths(const config::Machine& machine, const std::vector<Primitive>& primitives,
                                  config::Objective objective, const std::vector<Plan>& plans,
                                  const std::vector<std::vector<double>>& toolpath_minutes) {
  ToolpathRanking out;
  for (std::size_t k = 0; k < plans.size() && k < toolpath_minutes.size(); ++k)
    for (std::size_t s = 0; s < plans[k].steps.size() && s < toolpath_minutes[k].size(); ++s)
      out.estimates_off += estimate_off(estimated_work(machine, primitives, plans[k].steps[s]), toolpath_minutes[k][s]);
  out.order.resize(plans.size());
  std::iota(out.order.begin(), out.order.end(), 0);
  // Cost factors are not times: their ranking stands, the toolpaths' times are only shown.
  out.ranked = out.estimates_off > 0 && toolpath_minutes.size() == plans.size() &&
               objective != config::Objective::CostFactor;
  if (!out.ranked) return out;
  for (std::size_t k = 0; k < plans.size(); ++k)
    out.costs.push_back(cost_with_toolpaths(machine, primitives, objective, plans[k], toolpath_minutes[k]));
  std::stable_sort(out.order.begin(), out.order.end(),
                   [&](std::size_t a, std::size_t b) { return out.costs[a] < out.costs[b]; });
  return out;
}

}  // namespace hybridctl::planner
