// The plan search as it was before issue 15 (commit 2e6a14a, planner/search/search.cpp): A* with
// the per-atom bound only, every order of every block, no anytime fallback. Kept here as the
// baseline planner_bench measures the search against: verbatim but for its namespace, and
// for the rule of actions (without learned shortfalls or reach) and the duplicate keys, which
// it takes from the planner as they were.

#include "bench/baseline_astar.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <deque>
#include <functional>
#include <limits>
#include <queue>
#include <unordered_map>

#include "common/hash.hpp"
#include "planner/problem/actions.hpp"
#include "planner/search/steps.hpp"

namespace hybridctl::planner::baseline {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

double volume_of_bits(const PlanningProblem& p, const std::vector<std::uint64_t>& bits) {
  double v = 0;
  for (std::size_t w = 0; w < bits.size(); ++w)
    for (std::uint64_t b = bits[w]; b; b &= b - 1) v += p.atoms[w * 64 + std::size_t(std::countr_zero(b))].volume;
  return v;
}

// The state after applying primitive `i`, and the volume it really changes: the planner's
// rule of actions (planner/problem/actions.hpp) as it was, with nothing learned and nothing
// out of a head's reach.
bool apply(const PlanningProblem& p, const AtomSet& state, int i, AtomSet& next, double& volume) {
  std::vector<std::uint64_t> changed;
  action_effect(p, state, i, true, next, changed);
  if (std::all_of(changed.begin(), changed.end(), [](std::uint64_t w) { return w == 0; })) return false;
  volume = volume_of_bits(p, changed);
  return true;
}

double fixed_cost_without_refixture(const PlanningProblem& p, int previous, int next) {
  if (previous < 0) return 0;
  const PrimitiveSpec& a = p.primitives[std::size_t(previous)];
  const PrimitiveSpec& b = p.primitives[std::size_t(next)];
  double c = 0;
  if (a.tool != b.tool) c += p.fixed.tool_change;
  if (a.setup != b.setup) c += p.fixed.setup_change;
  if (a.mode != b.mode) c += p.fixed.mode_switch;
  return c;
}

bool allowed(const PlanningProblem& p, int i, bool first, const std::vector<std::uint8_t>& uses) {
  const PrimitiveSpec& prim = p.primitives[std::size_t(i)];
  if (uses[std::size_t(i)] >= p.max_uses) return false;
  if (first) return prim.mode == Mode::Additive;  // C3
  return !prim.raw_stock;                         // C4
}

// Per atom, the primitives that can deposit (or remove) it, cheapest first.
struct Suppliers {
  std::vector<std::vector<int>> additive, subtractive;
};

Suppliers suppliers_of(const PlanningProblem& p) {
  Suppliers s;
  s.additive.resize(p.atoms.size());
  s.subtractive.resize(p.atoms.size());
  for (int i = 0; i < int(p.primitives.size()); ++i) {
    const PrimitiveSpec& prim = p.primitives[std::size_t(i)];
    for (std::size_t a = 0; a < p.atoms.size(); ++a)
      if (prim.atoms.test(int(a))) (prim.mode == Mode::Additive ? s.additive : s.subtractive)[a].push_back(i);
  }
  auto by_cost = [&](int x, int y) { return p.primitives[std::size_t(x)].cost_per_mm3 < p.primitives[std::size_t(y)].cost_per_mm3; };
  for (auto& l : s.additive) std::sort(l.begin(), l.end(), by_cost);
  for (auto& l : s.subtractive) std::sort(l.begin(), l.end(), by_cost);
  return s;
}

double heuristic(const PlanningProblem& p, const Suppliers& sup, const AtomSet& state, const std::vector<std::uint8_t>& uses,
                 bool first) {
  double h = 0;
  for (std::size_t a = 0; a < p.atoms.size(); ++a) {
    const AtomSpec& atom = p.atoms[a];
    const bool present = state.test(int(a));
    if (atom.must_in && !present) {
      // A later deposition may use any additive primitive still available after the
      // first step, or (at the start) any additive one.
      double best = kInfinity;
      for (int i : sup.additive[a]) {
        const PrimitiveSpec& prim = p.primitives[std::size_t(i)];
        if (uses[std::size_t(i)] >= p.max_uses || (!first && prim.raw_stock)) continue;
        best = prim.cost_per_mm3;
        break;
      }
      if (best == kInfinity) return kInfinity;
      h += best * atom.volume;
    } else if (atom.must_out && present) {
      double best = kInfinity;
      for (int i : sup.subtractive[a]) {
        if (uses[std::size_t(i)] >= p.max_uses) continue;
        best = p.primitives[std::size_t(i)].cost_per_mm3;
        break;
      }
      if (best == kInfinity) return kInfinity;
      h += best * atom.volume;
    }
  }
  return h / p.normaliser;
}

struct Node {
  int parent = -1;
  int primitive = -1;
  int depth = 0;
  double g = 0;
  double step_volume = 0;
  double step_cost = 0;
  AtomSet state;
  std::vector<std::uint8_t> uses;
};

using KeyHash = WordsHash;

// Duplicate detection key: state, uses and the last primitive (fixed costs depend on it).
std::vector<std::uint64_t> key_of(const Node& n) {
  std::vector<std::uint64_t> k = n.state.words();
  detail::append_uses(k, n.uses);
  k.push_back(std::uint64_t(std::int64_t(n.primitive)));
  return k;
}

Plan plan_from(const std::deque<Node>& nodes, int leaf) {
  Plan plan;
  plan.cost = nodes[std::size_t(leaf)].g;
  plan.final_state = nodes[std::size_t(leaf)].state;
  for (int n = leaf; nodes[std::size_t(n)].parent >= 0; n = nodes[std::size_t(n)].parent) {
    const Node& node = nodes[std::size_t(n)];
    plan.steps.push_back({node.primitive, node.step_volume, node.step_cost});
  }
  std::reverse(plan.steps.begin(), plan.steps.end());
  return plan;
}

}  // namespace

bool is_goal_old(const PlanningProblem& p, const AtomSet& state) {
  for (std::size_t a = 0; a < p.atoms.size(); ++a) {
    const bool present = state.test(int(a));
    if (p.atoms[a].must_in && !present) return false;
    if (p.atoms[a].must_out && present) return false;
  }
  return true;
}

std::vector<Plan> find_plans(const PlanningProblem& p, const SearchOptions& options, SearchStats* stats) {  // NOLINT: the A* of commit 2e6a14a
  SearchStats local;
  SearchStats& st = stats ? *stats : local;
  st = {};
  std::vector<Plan> plans;
  const Suppliers sup = suppliers_of(p);
  const int n = int(p.primitives.size());

  std::deque<Node> nodes;  // no reallocation: memory grows by blocks
  nodes.push_back({-1, -1, 0, 0, 0, 0, AtomSet(int(p.atoms.size())), std::vector<std::uint8_t>(std::size_t(n), 0)});
  struct Entry {
    double f, g;
    std::int64_t seq;
    int node;
  };
  auto worse = [](const Entry& a, const Entry& b) {
    if (a.f != b.f) return a.f > b.f;
    if (a.g != b.g) return a.g < b.g;  // prefer deeper on ties: reaches goals sooner
    return a.seq > b.seq;
  };
  std::priority_queue<Entry, std::vector<Entry>, decltype(worse)> open(worse);
  std::int64_t seq = 0;
  const double h0 = heuristic(p, sup, nodes[0].state, nodes[0].uses, true);
  if (h0 == kInfinity) {
    st.exhausted = true;
    return plans;
  }
  st.weight = options.weight;
  open.push({options.weight * h0, 0, seq++, 0});
  std::unordered_map<std::vector<std::uint64_t>, int, KeyHash> pops;

  while (!open.empty() && int(plans.size()) < options.top_k) {
    const Entry e = open.top();
    open.pop();
    const int id = e.node;
    if (id != 0) {
      int& count = pops[key_of(nodes[std::size_t(id)])];
      // k cheapest arrivals at this key suffice, plus one for each plan turned down.
      if (count >= options.top_k + st.rejected) continue;
      ++count;
    }
    if (id != 0 && is_goal_old(p, nodes[std::size_t(id)].state)) {
      Plan plan = plan_from(nodes, id);
      if (!options.accept || options.accept(plan)) {
        plans.push_back(std::move(plan));
      } else if (++st.rejected >= options.max_rejected) {
        st.limit_reached = true;
        break;
      }
      continue;
    }
    if (st.expanded >= options.max_expansions || std::int64_t(nodes.size()) >= options.max_states) {
      st.limit_reached = true;
      break;
    }
    ++st.expanded;
    const bool first = id == 0;
    for (int i = 0; i < n; ++i) {
      if (!allowed(p, i, first, nodes[std::size_t(id)].uses)) continue;
      AtomSet next;
      double volume = 0;
      if (!apply(p, nodes[std::size_t(id)].state, i, next, volume)) continue;
      Node child;
      child.parent = id;
      child.primitive = i;
      child.depth = nodes[std::size_t(id)].depth + 1;
      child.step_volume = volume;
      child.step_cost =
          (p.primitives[std::size_t(i)].cost_per_mm3 * volume + fixed_cost_without_refixture(p, nodes[std::size_t(id)].primitive, i)) /
          p.normaliser;
      child.g = nodes[std::size_t(id)].g + child.step_cost;
      child.state = std::move(next);
      child.uses = nodes[std::size_t(id)].uses;
      ++child.uses[std::size_t(i)];
      const double h = heuristic(p, sup, child.state, child.uses, false);
      if (h == kInfinity) continue;
      ++st.generated;
      nodes.push_back(std::move(child));
      const int child_id = int(nodes.size()) - 1;
      open.push({nodes.back().g + options.weight * h, nodes.back().g, seq++, child_id});
    }
  }
  if (open.empty() && int(plans.size()) < options.top_k) st.exhausted = true;
  return plans;
}


}  // namespace hybridctl::planner::baseline
