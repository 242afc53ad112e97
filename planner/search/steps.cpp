// The plan search's steps (search_steps.hpp), the exhaustive enumerator, the reachability
// exploration, the goal test and the paper's plan expression (search.hpp).

#include "planner/search/steps.hpp"

#include <algorithm>
#include <bit>
#include <deque>
#include <functional>
#include <string>
#include <tuple>
#include <unordered_set>

namespace hybridctl::planner {
namespace detail {

bool allowed(const PlanningProblem& p, int i, bool first, const std::vector<std::uint8_t>& uses) {
  const PrimitiveSpec& prim = p.primitives[std::size_t(i)];
  if (uses[std::size_t(i)] >= p.max_uses) return false;
  if (first) return !prim.never_first && prim.mode == Mode::Additive && (!p.start_from_stock || prim.raw_stock);  // C3
  return !prim.raw_stock;                         // C4
}

std::vector<int> sequence_of(const Plan& plan) { return plan.primitives(); }

std::vector<std::uint64_t> effect_of(const PlanningProblem& p, const std::vector<int>& sequence) {
  std::vector<std::uint64_t> key;
  AtomSet state(int(p.atoms.size()));
  auto& s = state.words();
  for (const int i : sequence) {
    const PrimitiveSpec& prim = p.primitives[std::size_t(i)];
    key.push_back(std::hash<std::string>{}(prim.tool + '\n' + prim.setup) ^ std::uint64_t(prim.mode == Mode::Additive));
    const auto& a = prim.atoms.words();
    for (std::size_t w = 0; w < s.size(); ++w) {
      key.push_back(prim.mode == Mode::Additive ? a[w] & ~s[w] : a[w] & s[w]);
      s[w] = prim.mode == Mode::Additive ? s[w] | a[w] : s[w] & ~a[w];
    }
  }
  return key;
}

bool in_block_order(const PlanningProblem& p, int last, int next) {
  if (last < 0) return true;
  const PrimitiveSpec& a = p.primitives[std::size_t(last)];
  const PrimitiveSpec& b = p.primitives[std::size_t(next)];
  if (a.mode != b.mode || a.tool != b.tool || a.setup != b.setup) return true;
  return std::make_tuple(!a.raw_stock, a.cost_per_mm3, last) < std::make_tuple(!b.raw_stock, b.cost_per_mm3, next);
}

void append_uses(std::vector<std::uint64_t>& key, const std::vector<std::uint8_t>& uses) {
  std::uint64_t packed = 0;
  int shift = 0;
  for (std::uint8_t u : uses) {
    packed |= std::uint64_t(u) << shift;
    shift += 8;
    if (shift == 64) {
      key.push_back(packed);
      packed = 0;
      shift = 0;
    }
  }
  key.push_back(packed);
}

GoalFilter::GoalFilter(const PlanningProblem& p, const SearchOptions& o, const std::set<std::vector<int>>& known,
                       SearchStats& st)
    : p_(p), o_(o), known_(known), st_(st), rejected_before_(st.rejected) {
  if (o_.distinct_effects)
    for (const std::vector<int>& k : known_) effects_.insert(effect_of(p_, k));
}

GoalFilter::Verdict GoalFilter::judge(const Plan& plan) {
  const std::vector<int> sequence = sequence_of(plan);
  if (known_.count(sequence)) return Pass;
  if (o_.distinct_effects && !effects_.insert(effect_of(p_, sequence)).second) {
    ++same_effect_;
    return Pass;
  }
  if (o_.known_to_fail && o_.known_to_fail(plan)) {
    ++known_to_fail_;
    ++st_.known_to_fail;
    return Pass;
  }
  if (!o_.accept || o_.accept(plan)) return Take;
  ++st_.rejected;
  if (o_.interrupt && o_.interrupt()) {
    st_.interrupted = true;
    return Stop;
  }
  return st_.rejected >= o_.max_rejected ? Stop : Pass;
}

}  // namespace detail

using detail::allowed;

Reachability explore_reachable(const PlanningProblem& p, std::int64_t max_states) {
  Reachability r;
  const int n = int(p.primitives.size());
  const auto wrong = [&](const AtomSet& state) {
    double v = 0;
    for (std::size_t a = 0; a < p.atoms.size(); ++a) {
      const bool present = state.test(int(a));
      if ((p.atoms[a].must_in && !present) || (p.atoms[a].must_out && present)) v += p.atoms[a].volume;
    }
    return v;
  };
  std::unordered_set<AtomSet, AtomSetHash> seen;
  std::deque<AtomSet> queue;
  const AtomSet empty(int(p.atoms.size()));
  r.nearest = empty;
  r.wrong_volume = wrong(empty);
  const std::vector<std::uint8_t> no_uses(std::size_t(n), 0);
  // The empty state first, where raw stock may start the plan (C3, C4); later states
  // never take raw stock, so an empty state reached again is another state than the start.
  for (bool first = true; first || !queue.empty(); first = false) {
    AtomSet state = first ? empty : std::move(queue.front());
    if (!first) queue.pop_front();
    for (int i = 0; i < n; ++i) {
      if (!allowed(p, i, first, no_uses)) continue;
      AtomSet next;
      double volume = 0;
      if (!apply(p, state, i, next, volume, first) || seen.count(next)) continue;
      if (std::int64_t(seen.size()) >= max_states) return r;
      ++r.states;
      const double w = wrong(next);
      if (w < r.wrong_volume) r.wrong_volume = w, r.nearest = next;
      if (is_goal(p, next)) {
        r.goal = true;
        r.nearest = next;
        r.wrong_volume = w;
        return r;
      }
      seen.insert(next);
      queue.push_back(std::move(next));
    }
  }
  r.complete = true;
  return r;
}

std::vector<Plan> enumerate_plans(const PlanningProblem& p, std::size_t limit) {
  std::vector<Plan> plans;
  const int n = int(p.primitives.size());
  Plan current;
  std::vector<std::uint8_t> uses(std::size_t(n), 0);
  std::function<void(const AtomSet&, int, double)> visit = [&](const AtomSet& state, int last, double cost) {
    if (last >= 0 && is_goal(p, state)) {
      Plan done = current;
      done.cost = cost;
      done.final_state = state;
      plans.push_back(std::move(done));
      return;
    }
    for (int i = 0; i < n; ++i) {
      if (!allowed(p, i, last < 0, uses)) continue;
      AtomSet next;
      double volume = 0;
      if (!apply(p, state, i, next, volume, last < 0)) continue;
      const double step = (p.primitives[std::size_t(i)].cost_per_mm3 * volume + fixed_cost(p, last, i)) / p.normaliser;
      current.steps.push_back({i, volume, step});
      ++uses[std::size_t(i)];
      visit(next, i, cost + step);
      --uses[std::size_t(i)];
      current.steps.pop_back();
    }
  };
  visit(AtomSet(int(p.atoms.size())), -1, 0);
  std::stable_sort(plans.begin(), plans.end(), [](const Plan& a, const Plan& b) { return a.cost < b.cost; });
  if (plans.size() > limit) plans.resize(limit);
  return plans;
}

}  // namespace hybridctl::planner
