#include "planner/costing/costs.hpp"

#include <cmath>
#include <cstdio>

namespace hybridctl::planner {
namespace {

constexpr double kMm3PerCm3 = 1000.0;
constexpr double kGramsPerKg = 1000.0;

const config::AdditiveHead* head_of(const config::Machine& m, const Primitive& p) {
  if (p.mode != Mode::Additive || p.kind == PrimitiveKind::RawStock || p.kind == PrimitiveKind::File) return nullptr;
  return m.find_head(p.capability);
}

const config::CuttingTool* tool_of(const config::Machine& m, const Primitive& p) {
  return p.mode == Mode::Subtractive && p.tool_number > 0 ? m.find_tool(p.tool_number) : nullptr;
}

// kg per mm³ at a density in g/cm³.
double kg_per_mm3(double density) { return density / kMm3PerCm3 / kGramsPerKg; }

double per_hour_to_per_minute(double rate) { return rate / 60.0; }

}  // namespace

Estimate per_mm3(const config::Machine& m, const Primitive& p) {
  const double money_per_minute = per_hour_to_per_minute(m.costs.machine_rate);
  if (p.kind == PrimitiveKind::RawStock) {
    config::RawStock bought;  // a stock given as a file is priced as the default stock
    for (const config::RawStock& s : m.raw_stocks)
      if (!p.from_file && s.name == p.capability) bought = s;
    return {0, kg_per_mm3(bought.density) * bought.price_per_kg};
  }
  if (const config::AdditiveHead* h = head_of(m, p)) {
    const double minutes = 1.0 / h->volume_rate();
    const double material = kg_per_mm3(h->material.density) * h->material.price_per_kg / h->material.efficiency;
    return {minutes, minutes * money_per_minute + material};
  }
  if (const config::CuttingTool* t = tool_of(m, p)) {
    const double minutes = 1.0 / t->volume_rate();
    return {minutes, minutes * (money_per_minute + t->tool_price / t->tool_life)};
  }
  return {};
}

bool refixture_setup(const config::Machine& m, const Primitive& p) {
  const config::Setup* s = p.setup.empty() ? nullptr : m.find_setup(p.setup);
  return s && s->manual_refixture;
}

Estimate change_between(const config::Machine& m, const Primitive& from, const Primitive& to) {
  const config::Costs& c = m.costs;
  double minutes = 0;
  if (from.capability != to.capability) minutes += c.tool_change / 60.0;
  if (from.mode != to.mode) minutes += c.head_switch / 60.0;
  if (from.setup != to.setup)
    minutes += refixture_setup(m, from) || refixture_setup(m, to) ? c.refixture : c.setup_change / 60.0;
  return {minutes, minutes * per_hour_to_per_minute(c.machine_rate)};
}

PlanEstimate estimate_plan(const config::Machine& m, const std::vector<Primitive>& primitives, const Plan& plan) {
  PlanEstimate e;
  const Primitive* previous = nullptr;
  for (const PlanStep& step : plan.steps) {
    const Primitive& p = primitives[std::size_t(step.primitive)];
    const Estimate rate = per_mm3(m, p);
    Estimate s{rate.minutes * step.volume, rate.money * step.volume};
    // After the raw stock, as at the start, no change: the stock is clamped in the first
    // action's setup with its instrument loaded (planner/problem/actions.hpp, fixed_cost).
    const Estimate change =
        previous && previous->kind != PrimitiveKind::RawStock ? change_between(m, *previous, p) : Estimate{};
    s += change;
    e.steps.push_back(s);
    e.changes.push_back(change);
    e.total += s;
    previous = &p;
  }
  return e;
}

double objective_per_mm3(const config::Machine& m, config::Objective objective, const Primitive& p) {
  if (objective == config::Objective::CostFactor || p.kind == PrimitiveKind::File) return p.cost_per_mm3;
  const Estimate e = per_mm3(m, p);
  return objective == config::Objective::Time ? e.minutes : e.money;
}

FixedCosts objective_fixed_costs(const config::Machine& m, config::Objective objective) {
  const config::Planning& legacy = m.planning;
  if (objective == config::Objective::CostFactor)
    return {legacy.tool_change_cost, legacy.setup_change_cost, legacy.mode_switch_cost, legacy.setup_change_cost};
  const config::Costs& c = m.costs;
  const double unit = objective == config::Objective::Time ? 1.0 : per_hour_to_per_minute(c.machine_rate);
  return {c.tool_change / 60.0 * unit, c.setup_change / 60.0 * unit, c.head_switch / 60.0 * unit, c.refixture * unit};
}

std::string duration_text(double minutes) {
  char text[48];
  if (minutes < 1) {
    std::snprintf(text, sizeof text, "%.0f s", minutes * 60);
  } else if (minutes < 60) {
    std::snprintf(text, sizeof text, "%.0f min", minutes);
  } else {
    const long whole = std::lround(minutes);
    std::snprintf(text, sizeof text, "%ld h %02ld min", whole / 60, whole % 60);
  }
  return text;
}

std::string money_text(double money, const std::string& currency) {
  char text[64];
  std::snprintf(text, sizeof text, "%.2f %s", money, currency.c_str());
  return text;
}

}  // namespace hybridctl::planner
