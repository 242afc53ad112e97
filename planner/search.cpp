#include "planner/search.hpp"

#include "planner/search_bound.hpp"

#include <algorithm>
#include <bit>
#include <chrono>
#include <set>
#include <tuple>
#include <cmath>
#include <deque>
#include <functional>
#include <limits>
#include <queue>
#include <unordered_map>
#include <unordered_set>

namespace hybridctl::planner {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

double volume_of_bits(const PlanningProblem& p, const std::vector<std::uint64_t>& bits) {
  double v = 0;
  for (std::size_t w = 0; w < bits.size(); ++w)
    for (std::uint64_t b = bits[w]; b; b &= b - 1) v += p.atoms[w * 64 + std::size_t(std::countr_zero(b))].volume;
  return v;
}

// Whether material in `state` lies over an atom of `deposited` out of the head's reach.
bool blocked(const std::vector<AtomSet>& blocked_by, const AtomSet& state, const std::vector<std::uint64_t>& deposited) {
  const auto& s = state.words();
  for (std::size_t w = 0; w < deposited.size(); ++w)
    for (std::uint64_t b = deposited[w]; b; b &= b - 1) {
      const auto& over = blocked_by[w * 64 + std::size_t(std::countr_zero(b))].words();
      for (std::size_t k = 0; k < over.size(); ++k)
        if (over[k] & s[k]) return true;
    }
  return false;
}

// Whether an atom of the first layer in `deposited` has nothing to carry it: no plate (the
// state holds material, so the plan did not start here) and no carrier present.
bool floating(const DepositFooting& footing, const AtomSet& state, const std::vector<std::uint64_t>& deposited) {
  const auto& s = state.words();
  if (std::all_of(s.begin(), s.end(), [](std::uint64_t w) { return w == 0; })) return false;
  for (std::size_t w = 0; w < deposited.size(); ++w)
    for (std::uint64_t b = deposited[w]; b; b &= b - 1) {
      const std::size_t atom = w * 64 + std::size_t(std::countr_zero(b));
      if (footing.kind[atom] != DepositFooting::NeedsCarrier) continue;
      const auto& carriers = footing.carriers[atom].words();
      bool carried = false;
      for (std::size_t k = 0; k < carriers.size() && !carried; ++k) carried = (carriers[k] & s[k]) != 0;
      if (!carried) return true;
    }
  return false;
}

// The state after applying primitive `i`, and the volume it really changes; false when
// it changes nothing or cannot be taken in this state.
bool apply(const PlanningProblem& p, const AtomSet& state, int i, AtomSet& next, double& volume) {
  const PrimitiveSpec& prim = p.primitives[std::size_t(i)];
  const auto& s = state.words();
  const auto& a = prim.atoms.words();
  std::vector<std::uint64_t> changed(s.size());
  next = state;
  auto& n = next.words();
  bool any = false;
  for (std::size_t w = 0; w < s.size(); ++w) {
    if (prim.mode == Mode::Additive) {
      changed[w] = a[w] & ~s[w];
      n[w] = s[w] | a[w];
    } else {
      changed[w] = a[w] & s[w];
      n[w] = s[w] & ~a[w];
    }
    any = any || changed[w];
  }
  if (!any) return false;
  if (prim.mode == Mode::Additive && prim.blocked_by && blocked(*prim.blocked_by, state, changed)) return false;
  if (prim.mode == Mode::Additive && prim.footing && floating(*prim.footing, state, changed)) return false;
  volume = volume_of_bits(p, changed);
  return true;
}

double fixed_cost(const PlanningProblem& p, int previous, int next) {
  if (previous < 0) return 0;
  const PrimitiveSpec& a = p.primitives[std::size_t(previous)];
  const PrimitiveSpec& b = p.primitives[std::size_t(next)];
  double c = 0;
  if (a.tool != b.tool) c += p.fixed.tool_change;
  if (a.setup != b.setup) c += a.refixture || b.refixture ? p.fixed.refixture : p.fixed.setup_change;
  if (a.mode != b.mode) c += p.fixed.mode_switch;
  return c;
}

bool allowed(const PlanningProblem& p, int i, bool first, const std::vector<std::uint8_t>& uses) {
  const PrimitiveSpec& prim = p.primitives[std::size_t(i)];
  if (uses[std::size_t(i)] >= p.max_uses) return false;
  if (first) return prim.mode == Mode::Additive && (!p.start_from_stock || prim.raw_stock);  // C3
  return !prim.raw_stock;                         // C4
}

struct Node {
  int parent = -1;
  int primitive = -1;
  double g = 0;
  double step_volume = 0;
  double step_cost = 0;
  bool bounded = false;  // h is the full bound, not the quick one
  AtomSet state;
  std::vector<std::uint8_t> uses;
};

struct KeyHash {
  std::size_t operator()(const std::vector<std::uint64_t>& k) const {
    std::uint64_t h = 0xcbf29ce484222325ull;
    for (std::uint64_t w : k) h = (h ^ w) * 0x100000001b3ull, h ^= h >> 29;
    return std::size_t(h);
  }
};

// Duplicate detection key: state, uses and the last primitive (fixed costs depend on it).
std::vector<std::uint64_t> key_of(const Node& n) {
  std::vector<std::uint64_t> k = n.state.words();
  std::uint64_t packed = 0;
  int shift = 0;
  for (std::uint8_t u : n.uses) {
    packed |= std::uint64_t(u) << shift;
    shift += 8;
    if (shift == 64) {
      k.push_back(packed);
      packed = 0;
      shift = 0;
    }
  }
  k.push_back(packed);
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

std::vector<int> sequence_of(const Plan& plan) {
  std::vector<int> s;
  for (const PlanStep& step : plan.steps) s.push_back(step.primitive);
  return s;
}

// What a plan does, step by step: each step's tool, setup and mode and the atoms it
// changes. Two plans with the same effect differ only in which primitive names a step
// (a whole-part deposit after a band was milled deposits what the band's deposit would).
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

using Clock = std::chrono::steady_clock;

// Whether `next` may follow `last` when one order per block is kept: within a block
// (same mode, tool and setup) raw stock first, then by cost per mm^3, then by index.
bool in_block_order(const PlanningProblem& p, int last, int next) {
  if (last < 0) return true;
  const PrimitiveSpec& a = p.primitives[std::size_t(last)];
  const PrimitiveSpec& b = p.primitives[std::size_t(next)];
  if (a.mode != b.mode || a.tool != b.tool || a.setup != b.setup) return true;
  return std::make_tuple(!a.raw_stock, a.cost_per_mm3, last) < std::make_tuple(!b.raw_stock, b.cost_per_mm3, next);
}

// One best-first search (A*, or weighted A* for weight > 1) from the empty state.
class Search {
 public:
  Search(const PlanningProblem& p, const SearchOptions& o, const LowerBound& bound, Clock::time_point deadline,
         const std::set<std::vector<int>>& known, SearchStats& st, double prune_at = kInfinity)
      : p_(p), o_(o), bound_(bound), deadline_(deadline), known_(known), st_(st), prune_at_(prune_at) {
    if (o_.distinct_effects)
      for (const std::vector<int>& k : known_) effects_.insert(effect_of(p_, k));
  }

  // Accepted plans not in `known`, cheapest first (by f), at most `wanted`.
  std::vector<Plan> run(int wanted);
  // No plan the search did not return costs less than this (meaningful for weight 1).
  double frontier() const { return frontier_; }
  bool stopped_at_limit() const { return limit_; }

 private:
  struct Entry {
    double f, g;
    std::int64_t seq;
    int node;
  };
  struct Worse {
    bool operator()(const Entry& a, const Entry& b) const {
      if (a.f != b.f) return a.f > b.f;
      if (a.g != b.g) return a.g < b.g;  // prefer deeper on ties: reaches goals sooner
      return a.seq > b.seq;
    }
  };
  bool out_of_room() const;
  void expand(int id);

  const PlanningProblem& p_;
  const SearchOptions& o_;
  const LowerBound& bound_;
  Clock::time_point deadline_;
  const std::set<std::vector<int>>& known_;
  SearchStats& st_;
  double prune_at_;  // plans costing this or more are of no use
  std::deque<Node> nodes_;  // no reallocation: memory grows by blocks
  std::priority_queue<Entry, std::vector<Entry>, Worse> open_;
  std::int64_t seq_ = 0;
  double frontier_ = kInfinity;
  bool limit_ = false;
  std::set<std::vector<std::uint64_t>> effects_;  // of the plans returned or known (distinct_effects)
  std::int64_t same_effect_ = 0;  // goal plans skipped as doing what one returned does
};

bool Search::out_of_room() const {
  if (st_.expanded >= o_.max_expansions || std::int64_t(nodes_.size()) >= o_.max_states) return true;
  // The clock is read every 256 expansions: cheap, and often enough.
  return deadline_ != Clock::time_point::max() && (st_.expanded & 255) == 0 && Clock::now() >= deadline_;
}

void Search::expand(int id) {
  const int n = int(p_.primitives.size());
  const int last = nodes_[std::size_t(id)].primitive;
  for (int i = 0; i < n; ++i) {
    if (!allowed(p_, i, id == 0, nodes_[std::size_t(id)].uses)) continue;
    if (o_.block_orders == BlockOrders::Cheapest && !in_block_order(p_, last, i)) continue;
    AtomSet next;
    double volume = 0;
    if (!apply(p_, nodes_[std::size_t(id)].state, i, next, volume)) continue;
    Node child;
    child.parent = id;
    child.primitive = i;
    child.step_volume = volume;
    child.step_cost = (p_.primitives[std::size_t(i)].cost_per_mm3 * volume + fixed_cost(p_, last, i)) / p_.normaliser;
    child.g = nodes_[std::size_t(id)].g + child.step_cost;
    child.state = std::move(next);
    child.uses = nodes_[std::size_t(id)].uses;
    ++child.uses[std::size_t(i)];
    // The quick bound orders the child for now; the full one is computed when it comes
    // up (most children never do).
    const double h = bound_.quick(child.state, child.uses, i);
    if (h == kInfinity || child.g + h >= prune_at_) continue;
    ++st_.generated;
    nodes_.push_back(std::move(child));
    open_.push({nodes_.back().g + o_.weight * h, nodes_.back().g, seq_++, int(nodes_.size()) - 1});
  }
}

std::vector<Plan> Search::run(int wanted) {
  std::vector<Plan> plans;
  const int n = int(p_.primitives.size());
  nodes_.push_back({-1, -1, 0, 0, 0, true, AtomSet(int(p_.atoms.size())), std::vector<std::uint8_t>(std::size_t(n), 0)});
  const double h0 = bound_(nodes_[0].state, nodes_[0].uses, -1);
  if (h0 == kInfinity) {
    frontier_ = kInfinity;
    return plans;
  }
  open_.push({o_.weight * h0, 0, seq_++, 0});
  std::unordered_map<std::vector<std::uint64_t>, int, KeyHash> pops;
  const std::int64_t rejected_before = st_.rejected;
  while (!open_.empty() && int(plans.size()) < wanted) {
    const Entry e = open_.top();
    Node& node = nodes_[std::size_t(e.node)];
    if (!node.bounded) {
      node.bounded = true;
      const double h = bound_(node.state, node.uses, node.primitive);
      open_.pop();
      if (h == kInfinity || node.g + h >= prune_at_) continue;
      open_.push({node.g + o_.weight * h, node.g, e.seq, e.node});
      continue;
    }
    if (e.node != 0) {
      int& count = pops[key_of(node)];
      // k cheapest arrivals at this key suffice, plus one for each plan turned down.
      if (count >= o_.top_k + (st_.rejected - rejected_before) + same_effect_) {
        open_.pop();
        continue;
      }
      ++count;
    }
    if (e.node != 0 && is_goal(p_, node.state)) {
      open_.pop();
      Plan plan = plan_from(nodes_, e.node);
      if (known_.count(sequence_of(plan))) continue;
      if (o_.distinct_effects && !effects_.insert(effect_of(p_, sequence_of(plan))).second) {
        ++same_effect_;
        continue;
      }
      if (!o_.accept || o_.accept(plan)) {
        plans.push_back(std::move(plan));
      } else if (++st_.rejected >= o_.max_rejected) {
        limit_ = true;
        break;
      }
      continue;
    }
    if (out_of_room()) {
      limit_ = true;
      break;
    }
    open_.pop();
    ++st_.expanded;
    expand(e.node);
  }
  frontier_ = open_.empty() ? kInfinity : open_.top().f;
  return plans;
}

}  // namespace

bool is_goal(const PlanningProblem& p, const AtomSet& state) {
  for (std::size_t a = 0; a < p.atoms.size(); ++a) {
    const bool present = state.test(int(a));
    if (p.atoms[a].must_in && !present) return false;
    if (p.atoms[a].must_out && present) return false;
  }
  return true;
}

namespace {

// Plans from weighted A*, greedy first so that a plan comes soon, then at lower weights
// for cheaper ones while limits and time allow: the cheapest distinct ones found fill the
// slots the exact search left. A later search skips what cannot beat the dearest plan
// kept (g + h at least its cost).
void fill_with_weighted(const PlanningProblem& p, const SearchOptions& options, const LowerBound& bound,
                        Clock::time_point start, std::vector<Plan>& plans, SearchStats& st) {
  const double weights[] = {50.0, 5.0, 2.0};
  const std::size_t exact = plans.size();
  const int slots = options.top_k - int(exact);
  auto by_cost = [](const Plan& a, const Plan& b) { return a.cost < b.cost; };
  for (std::size_t k = 0; k < std::size(weights); ++k) {
    if (st.rejected >= options.max_rejected) break;
    Clock::time_point deadline = Clock::time_point::max();
    if (options.time_limit > 0) {
      const auto end = start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(options.time_limit));
      const auto now = Clock::now();
      if (now >= end) break;
      // Half of what is left, all of it for the last weight.
      deadline = k + 1 == std::size(weights) ? end : now + (end - now) / 2;
    }
    std::set<std::vector<int>> known;
    for (const Plan& plan : plans) known.insert(sequence_of(plan));
    SearchOptions weighted = options;
    weighted.weight = weights[k];
    SearchStats local;
    local.rejected = st.rejected;
    const bool full = int(plans.size() - exact) >= slots;
    Search search(p, weighted, bound, deadline, known, local, full ? plans.back().cost : kInfinity);
    std::vector<Plan> found = search.run(slots);
    st.expanded += local.expanded;
    st.generated += local.generated;
    st.rejected = local.rejected;
    for (Plan& plan : found) {
      plan.exact = false;
      plans.push_back(std::move(plan));
    }
    std::stable_sort(plans.begin() + std::ptrdiff_t(exact), plans.end(), by_cost);
    if (int(plans.size() - exact) > slots) plans.resize(exact + std::size_t(slots));
    if (!found.empty()) st.weight = weights[k];
  }
}

}  // namespace

std::vector<Plan> find_plans(const PlanningProblem& p, const SearchOptions& options, SearchStats* stats) {
  SearchStats local;
  SearchStats& st = stats ? *stats : local;
  st = {};
  const Clock::time_point start = Clock::now();
  const LowerBound bound(p);
  const std::set<std::vector<int>> none;
  Clock::time_point deadline = Clock::time_point::max();
  if (options.time_limit > 0)
    deadline = start + std::chrono::duration_cast<Clock::duration>(
                           std::chrono::duration<double>(options.time_limit * (options.weight > 1 ? 1.0 : 0.5)));
  Search exact(p, options, bound, deadline, none, st);
  std::vector<Plan> plans = exact.run(options.top_k);
  st.weight = options.weight;
  st.limit_reached = exact.stopped_at_limit();
  if (options.weight > 1) {
    for (Plan& plan : plans) plan.exact = false;
  } else if (int(plans.size()) < options.top_k && !exact.stopped_at_limit()) {
    st.exhausted = true;
  } else if (int(plans.size()) < options.top_k) {
    fill_with_weighted(p, options, bound, start, plans, st);
  }
  // Gaps against the best proven lower bound on the cheapest accepted plan.
  const bool first_exact = !plans.empty() && plans.front().exact;
  st.lower_bound = first_exact ? plans.front().cost : std::min(exact.frontier(), plans.empty() ? kInfinity : plans.front().cost);
  if (options.weight > 1) st.lower_bound = std::max(0.0, plans.empty() ? 0.0 : plans.front().cost / options.weight);
  if (st.lower_bound == kInfinity) st.lower_bound = 0;
  std::stable_sort(plans.begin(), plans.end(), [](const Plan& a, const Plan& b) { return a.cost < b.cost; });
  for (Plan& plan : plans)
    plan.gap = st.lower_bound > 0 ? std::max(0.0, plan.cost / st.lower_bound - 1) : (plan.cost > 0 ? kInfinity : 0.0);
  st.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return plans;
}

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
      if (!apply(p, state, i, next, volume) || seen.count(next)) continue;
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
      if (!apply(p, state, i, next, volume)) continue;
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
