// The rules of plans on the symbolic problem (actions.hpp).

#include "planner/problem/actions.hpp"

#include <algorithm>
#include <bit>
#include <string>

namespace hybridctl::planner {
namespace {

double volume_of_bits(const PlanningProblem& p, const std::vector<std::uint64_t>& bits) {
  double v = 0;
  for (std::size_t w = 0; w < bits.size(); ++w)
    for (std::uint64_t b = bits[w]; b; b &= b - 1) v += p.atoms[w * 64 + std::size_t(std::countr_zero(b))].volume;
  return v;
}

// Whether material in `state` lies over an atom of `deposited` out of the head's reach.
bool blocked(const AtomRelation& blocked_by, const AtomSet& state, const std::vector<std::uint64_t>& deposited) {
  const auto& s = state.words();
  for (std::size_t w = 0; w < deposited.size(); ++w)
    for (std::uint64_t b = deposited[w]; b; b &= b - 1)
      if (blocked_by.meets(w * 64 + std::size_t(std::countr_zero(b)), s)) return true;
  return false;
}

// Whether an atom of the first layer in `deposited` has nothing to carry it: no plate (the
// plan did not start with this action: a stock milled away entirely leaves none either)
// and no carrier present.
bool floating(const DepositFooting& footing, const AtomSet& state, const std::vector<std::uint64_t>& deposited) {
  const auto& s = state.words();
  for (std::size_t w = 0; w < deposited.size(); ++w)
    for (std::uint64_t b = deposited[w]; b; b &= b - 1) {
      const std::size_t atom = w * 64 + std::size_t(std::countr_zero(b));
      if (footing.kind[atom] != DepositFooting::NeedsCarrier) continue;
      if (!footing.carriers.meets(atom, s)) return true;
    }
  return false;
}

}  // namespace

void action_effect(const PlanningProblem& p, const AtomSet& state, int i, bool first, AtomSet& next,
                   std::vector<std::uint64_t>& changed) {
  const PrimitiveSpec& prim = p.primitives[std::size_t(i)];
  const auto& s = state.words();
  const auto& a = prim.atoms.words();
  changed.assign(s.size(), 0);
  next = state;
  auto& n = next.words();
  const auto& short_of = prim.falls_short.words();
  const bool begun = !first && !short_of.empty();
  for (std::size_t w = 0; w < s.size(); ++w) {
    const std::uint64_t does = begun && w < short_of.size() ? a[w] & ~short_of[w] : a[w];
    if (prim.mode == Mode::Additive) {
      changed[w] = does & ~s[w];
      n[w] = s[w] | does;
    } else {
      changed[w] = does & s[w];
      n[w] = s[w] & ~does;
    }
  }
}

PlanReplay replay_plan(const PlanningProblem& p, const Plan& plan, std::size_t steps) {
  const int n = int(p.atoms.size());
  const std::size_t taken = std::min(steps, plan.steps.size());
  PlanReplay out{AtomSet(n), std::vector<int>(std::size_t(n), -1), std::vector<std::vector<std::uint64_t>>(taken)};
  AtomSet next;
  for (std::size_t s = 0; s < taken; ++s) {
    action_effect(p, out.state, plan.steps[s].primitive, s == 0, next, out.changed[s]);
    for (std::size_t w = 0; w < out.changed[s].size(); ++w)
      for (std::uint64_t b = out.changed[s][w]; b; b &= b - 1) out.last[w * 64 + std::size_t(std::countr_zero(b))] = int(s);
    out.state = std::move(next);
  }
  return out;
}

bool apply(const PlanningProblem& p, const AtomSet& state, int i, AtomSet& next, double& volume, bool first) {
  const PrimitiveSpec& prim = p.primitives[std::size_t(i)];
  std::vector<std::uint64_t> changed;
  action_effect(p, state, i, first, next, changed);
  if (std::all_of(changed.begin(), changed.end(), [](std::uint64_t w) { return w == 0; })) return false;
  if (prim.mode == Mode::Additive && prim.blocked_by && blocked(*prim.blocked_by, state, changed)) return false;
  if (prim.mode == Mode::Additive && prim.footing && !first && floating(*prim.footing, state, changed)) return false;
  volume = volume_of_bits(p, changed);
  return true;
}

double fixed_cost(const PlanningProblem& p, int previous, int next) {
  // The raw stock is clamped in the setup the first action takes, with its instrument
  // loaded: as at the start of a plan without a stock, no change is due.
  if (previous < 0 || p.primitives[std::size_t(previous)].raw_stock) return 0;
  const PrimitiveSpec& a = p.primitives[std::size_t(previous)];
  const PrimitiveSpec& b = p.primitives[std::size_t(next)];
  double c = 0;
  if (a.tool != b.tool) c += p.fixed.tool_change;
  if (a.setup != b.setup) c += a.refixture || b.refixture ? p.fixed.refixture : p.fixed.setup_change;
  if (a.mode != b.mode) c += p.fixed.mode_switch;
  return c;
}

bool simulate(const PlanningProblem& p, const std::vector<int>& sequence, Plan& plan) {
  plan = {};
  AtomSet state(int(p.atoms.size()));
  int last = -1;
  for (const int i : sequence) {
    AtomSet next;
    double volume = 0;
    // A plan ends where it first reaches the goal.
    if (i < 0 || std::size_t(i) >= p.primitives.size()) return false;
    if ((last >= 0 && is_goal(p, state)) || !apply(p, state, i, next, volume, last < 0)) return false;
    const double cost = (p.primitives[std::size_t(i)].cost_per_mm3 * volume + fixed_cost(p, last, i)) / p.normaliser;
    plan.steps.push_back({i, volume, cost});
    plan.cost += cost;
    state = std::move(next);
    last = i;
  }
  plan.final_state = std::move(state);
  return true;
}

bool is_goal(const PlanningProblem& p, const AtomSet& state) {
  for (std::size_t a = 0; a < p.atoms.size(); ++a) {
    const bool present = state.test(int(a));
    if (p.atoms[a].must_in && !present) return false;
    if (p.atoms[a].must_out && present) return false;
  }
  return true;
}

std::string expression(const PlanningProblem& p, const Plan& plan) {
  std::string e;
  for (std::size_t s = 0; s < plan.steps.size(); ++s) {
    const PrimitiveSpec& prim = p.primitives[std::size_t(plan.steps[s].primitive)];
    if (s == 0) {
      e = prim.name;
    } else {
      e = "(" + e + (prim.mode == Mode::Additive ? " \u222A " : " \u2212 ") + prim.name + ")";
    }
  }
  return e;
}

}  // namespace hybridctl::planner
