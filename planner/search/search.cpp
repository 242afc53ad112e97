#include "planner/search/search.hpp"

#include "planner/search/backward.hpp"
#include "planner/search/bound.hpp"
#include "planner/search/greedy.hpp"
#include "planner/search/reduce.hpp"
#include "planner/search/steps.hpp"

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

using namespace detail;

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

// Duplicate detection key: state, uses and the last primitive (fixed costs depend on it).
std::vector<std::uint64_t> key_of(const Node& n) {
  std::vector<std::uint64_t> k = n.state.words();
  append_uses(k, n.uses);
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

using Clock = std::chrono::steady_clock;

// One best-first search (A*, or weighted A* for weight > 1) from the empty state.
class Search {
 public:
  Search(const PlanningProblem& p, const SearchOptions& o, const LowerBound& bound, Clock::time_point deadline,
         const std::set<std::vector<int>>& known, SearchStats& st, double prune_at = kInfinity)
      : p_(p), o_(o), bound_(bound), deadline_(deadline), goals_(p, o, known, st), st_(st), prune_at_(prune_at) {}

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
  GoalFilter goals_;
  SearchStats& st_;
  double prune_at_;  // plans costing this or more are of no use
  std::deque<Node> nodes_;  // no reallocation: memory grows by blocks
  std::priority_queue<Entry, std::vector<Entry>, Worse> open_;
  std::int64_t seq_ = 0;
  double frontier_ = kInfinity;
  bool limit_ = false;
};

bool Search::out_of_room() const {
  if (st_.expanded >= o_.max_expansions || std::int64_t(nodes_.size()) >= o_.max_states) return true;
  // The clock is read every 256 expansions: cheap, and often enough.
  return deadline_ != Clock::time_point::max() && (st_.expanded & 255) == 0 && Clock::now() >= deadline_;
}

void Search::expand(int id) {
  const int n = int(p_.primitives.size());
  const int last = nodes_[std::size_t(id)].primitive;
  // A primitive no suffix of a plan reaching the goal can hold leads nowhere from here.
  const std::vector<bool> usable = bound_.usable(nodes_[std::size_t(id)].uses, id == 0);
  for (int i = 0; i < n; ++i) {
    if (!usable[std::size_t(i)] || !allowed(p_, i, id == 0, nodes_[std::size_t(id)].uses)) continue;
    if (o_.block_orders == BlockOrders::Cheapest && !in_block_order(p_, last, i)) continue;
    AtomSet next;
    double volume = 0;
    if (!apply(p_, nodes_[std::size_t(id)].state, i, next, volume, id == 0)) continue;
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
    std::vector<bool> within = usable;  // the node's, less what the child cannot use
    if (child.uses[std::size_t(i)] >= p_.max_uses) within[std::size_t(i)] = false;
    for (std::size_t j = 0; j < within.size() && id == 0; ++j) within[j] = within[j] && !p_.primitives[j].raw_stock;
    const double h = bound_.quick(child.state, within, i);
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
      if (count >= o_.top_k + goals_.passed()) {
        open_.pop();
        continue;
      }
      ++count;
    }
    if (e.node != 0 && is_goal(p_, node.state)) {
      open_.pop();
      Plan plan = plan_from(nodes_, e.node);
      const GoalFilter::Verdict verdict = goals_.judge(plan);
      if (verdict == GoalFilter::Take) plans.push_back(std::move(plan));
      if (verdict != GoalFilter::Stop) continue;
      limit_ = true;
      break;
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

namespace {

// Plans from weighted A*, greedy first so that a plan comes soon, then at lower weights
// for cheaper ones while limits and time allow: the cheapest distinct ones found fill the
// slots the exact search left. A later search skips what cannot beat the dearest plan
// kept (g + h at least its cost).
template <class Make>
void fill_with_weighted(const SearchOptions& options, const Make& make, Clock::time_point start, std::vector<Plan>& plans,
                        SearchStats& st) {
  const double weights[] = {50.0, 5.0, 2.0};
  const std::size_t exact = std::size_t(std::count_if(plans.begin(), plans.end(), [](const Plan& p) { return p.exact; }));
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
    // With a plan to offer already, each pass is a quarter of the limit: one weight finds
    // plans in a few dozen expansions where another finds none in the whole limit (the
    // tube on a plate: w = 50 none in 10,000, w = 5 three in 24), and the time is better
    // spent on the next weight than on the rest of this one's.
    if (!plans.empty()) weighted.max_expansions = std::max<std::int64_t>(1, options.max_expansions / 4);
    SearchStats local;
    local.rejected = st.rejected;
    const bool full = int(plans.size() - exact) >= slots;
    auto search = make(weighted, deadline, known, local, full ? plans.back().cost : kInfinity);
    std::vector<Plan> found = search.run(slots);
    st.expanded += local.expanded;
    st.generated += local.generated;
    st.rejected = local.rejected;
    st.known_to_fail += local.known_to_fail;
    st.interrupted = local.interrupted;
    for (Plan& plan : found) {
      plan.exact = false;
      plans.push_back(std::move(plan));
    }
    std::stable_sort(plans.begin() + std::ptrdiff_t(exact), plans.end(), by_cost);
    if (int(plans.size() - exact) > slots) plans.resize(exact + std::size_t(slots));
    if (!found.empty()) st.weight = weights[k];
    if (st.interrupted) break;
  }
}

// How many plans greedy_sequences offers the filter at most: enough for top k after a few
// turned down, few enough that building them stays cheap.
constexpr std::size_t kGreedyCandidates = 24;

// The seeds, then plans built step by step (planner/search/greedy.hpp), cheapest first,
// judged as the search's are: those accepted take free slots after the exact plans.
void fill_with_greedy(const PlanningProblem& p, const SearchOptions& options, std::vector<Plan>& plans,
                      SearchStats& st) {
  const int slots = options.top_k - int(plans.size());
  if (slots <= 0) return;
  std::set<std::vector<int>> known;
  for (const Plan& plan : plans) known.insert(sequence_of(plan));
  GoalFilter goals(p, options, known, st);
  int taken = 0;
  // The seeds cheapest first, each once (the proofs' replays come in no order).
  std::vector<std::pair<double, std::vector<int>>> costed;
  for (const std::vector<int>& seed : options.seeds) {
    Plan plan;
    if (simulate(p, seed, plan) && is_goal(p, plan.final_state)) costed.emplace_back(plan.cost, seed);
  }
  std::sort(costed.begin(), costed.end());
  costed.erase(std::unique(costed.begin(), costed.end()), costed.end());
  std::vector<std::vector<int>> sequences;
  for (auto& c : costed) sequences.push_back(std::move(c.second));
  const std::size_t seeds = sequences.size();
  for (std::vector<int>& sequence : greedy_sequences(p, kGreedyCandidates)) sequences.push_back(std::move(sequence));
  for (std::size_t k = 0; k < sequences.size(); ++k) {
    if (taken >= slots || st.rejected >= options.max_rejected) break;
    Plan plan;
    if (!simulate(p, sequences[k], plan)) continue;
    const GoalFilter::Verdict verdict = goals.judge(plan);
    if (verdict == GoalFilter::Take) {
      plan.exact = false;
      plan.built = k >= seeds;
      plan.replayed = k < seeds;
      plans.push_back(std::move(plan));
      ++taken;
    }
    if (verdict == GoalFilter::Stop) break;
  }
}

// The exact search, then weighted ones when it stops at a limit, in one direction: `make`
// gives a search (Search or BackwardSearch) for the options, deadline, known plans, stats
// and cost to prune at.
template <class Make>
std::vector<Plan> exact_then_weighted(const PlanningProblem& p, const SearchOptions& options, const Make& make,
                                      SearchStats& st, Clock::time_point start) {
  const std::set<std::vector<int>> none;
  Clock::time_point deadline = Clock::time_point::max();
  if (options.time_limit > 0)
    deadline = start + std::chrono::duration_cast<Clock::duration>(
                           std::chrono::duration<double>(options.time_limit * (options.weight > 1 ? 1.0 : 0.5)));
  auto exact = make(options, deadline, none, st, kInfinity);
  std::vector<Plan> plans = exact.run(options.top_k);
  st.weight = options.weight;
  st.limit_reached = exact.stopped_at_limit();
  if (options.weight > 1) {
    for (Plan& plan : plans) plan.exact = false;
  } else if (int(plans.size()) < options.top_k && !exact.stopped_at_limit()) {
    st.exhausted = true;
  } else if (int(plans.size()) < options.top_k && !st.interrupted) {
    fill_with_greedy(p, options, plans, st);
    if (!st.interrupted) fill_with_weighted(options, make, start, plans, st);
  }
  // Gaps against the best proven lower bound on the cheapest accepted plan.
  const bool first_exact = !plans.empty() && plans.front().exact;
  st.lower_bound = first_exact ? plans.front().cost : std::min(exact.frontier(), plans.empty() ? kInfinity : plans.front().cost);
  if (options.weight > 1) st.lower_bound = std::max(0.0, plans.empty() ? 0.0 : plans.front().cost / options.weight);
  if (st.lower_bound == kInfinity) st.lower_bound = 0;
  std::stable_sort(plans.begin(), plans.end(), [](const Plan& a, const Plan& b) { return a.cost < b.cost; });
  for (Plan& plan : plans)
    plan.gap = st.lower_bound > 0 ? std::max(0.0, plan.cost / st.lower_bound - 1) : (plan.cost > 0 ? kInfinity : 0.0);
  return plans;
}

// Backwards when every atom is must-in or must-out and no action's reach or footing depends
// on the state before it (which only forward search knows as it goes). Free atoms let
// nearly every primitive come before nearly any suffix, and the backward bound has no
// share for them: on the B-axis machine's problems (a tolerance band of free atoms)
// backward search finds no plan where forward search finds three (docs/search.md).
bool backwards(const PlanningProblem& p, const SearchOptions& options) {
  if (options.direction != SearchDirection::Auto) return options.direction == SearchDirection::Backward;
  for (const PrimitiveSpec& prim : p.primitives)
    if (prim.blocked_by || prim.footing || !prim.falls_short.words().empty()) return false;
  for (const AtomSpec& atom : p.atoms)
    if (!atom.must_in && !atom.must_out) return false;
  return true;
}

// find_plans on the problem as given.
std::vector<Plan> search_plans(const PlanningProblem& p, const SearchOptions& options, SearchStats& st,
                               Clock::time_point start) {
  using Known = std::set<std::vector<int>>;
  if (backwards(p, options)) {
    const auto make = [&](const SearchOptions& o, Clock::time_point deadline, const Known& known, SearchStats& s,
                          double prune_at) { return BackwardSearch(p, o, deadline, known, s, prune_at); };
    return exact_then_weighted(p, options, make, st, start);
  }
  const LowerBound bound(p);
  const auto make = [&](const SearchOptions& o, Clock::time_point deadline, const Known& known, SearchStats& s,
                        double prune_at) { return Search(p, o, bound, deadline, known, s, prune_at); };
  return exact_then_weighted(p, options, make, st, start);
}

}  // namespace

std::vector<Plan> find_plans(const PlanningProblem& p, const SearchOptions& options, SearchStats* stats) {
  SearchStats local;
  SearchStats& st = stats ? *stats : local;
  st = {};
  const Clock::time_point start = Clock::now();
  std::vector<Plan> plans;
  if (!options.reduce) {
    plans = search_plans(p, options, st, start);
  } else if (const Reduction r = reduce(p); r.infeasible) {
    st.exhausted = true;  // no plan can reach the goal
  } else {
    // The search runs on the reduced problem; the caller's hook sees plans in its terms.
    SearchOptions inner = options;
    // Seeds in the reduced problem's terms: one that uses a primitive no plan can hold is
    // no plan.
    std::vector<int> reduced(p.primitives.size(), -1);
    for (std::size_t i = 0; i < r.primitive.size(); ++i) reduced[std::size_t(r.primitive[i])] = int(i);
    inner.seeds.clear();
    for (const std::vector<int>& seed : options.seeds) {
      std::vector<int> mapped;
      for (int i : seed)
        if (i >= 0 && std::size_t(i) < reduced.size() && reduced[std::size_t(i)] >= 0) mapped.push_back(reduced[std::size_t(i)]);
      if (mapped.size() == seed.size()) inner.seeds.push_back(std::move(mapped));
    }
    if (options.accept) inner.accept = [&](const Plan& plan) { return options.accept(lift(r, plan)); };
    if (options.known_to_fail)
      inner.known_to_fail = [&](const Plan& plan) { return options.known_to_fail(lift(r, plan)); };
    plans = search_plans(r.problem, inner, st, start);
    for (Plan& plan : plans) plan = lift(r, plan);
  }
  st.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return plans;
}

}  // namespace hybridctl::planner
