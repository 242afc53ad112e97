#include "planner/search/backward.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <unordered_map>

namespace hybridctl::planner::detail {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
// How far above the f it comes up at a node's children are stored, as a share of the bound
// at the start: wide enough that a node is seldom expanded more than a few times.
constexpr double kWindow = 0.002;

std::vector<std::uint64_t> mask_of(const PlanningProblem& p, bool (*in)(const AtomSpec&)) {
  std::vector<std::uint64_t> mask(std::size_t((p.atoms.size() + 63) / 64), 0);
  for (std::size_t a = 0; a < p.atoms.size(); ++a)
    if (in(p.atoms[a])) mask[a / 64] |= std::uint64_t{1} << (a % 64);
  return mask;
}

bool additive(const PlanningProblem& p, int i) { return p.primitives[std::size_t(i)].mode == Mode::Additive; }

}  // namespace

BackwardSearch::BackwardSearch(const PlanningProblem& p, const SearchOptions& o, Clock::time_point deadline,
                               const std::set<std::vector<int>>& known, SearchStats& st, double prune_at)
    : p_(p), o_(o), deadline_(deadline), goals_(p, o, known, st), st_(st), prune_at_(prune_at) {
  must_in_ = mask_of(p, [](const AtomSpec& a) { return a.must_in; });
  const auto must_out = mask_of(p, [](const AtomSpec& a) { return a.must_out; });
  adders_.resize(p.atoms.size());
  for (const PrimitiveSpec& prim : p.primitives) {
    adds_.push_back(prim.mode == Mode::Additive);
    rate_.push_back(prim.cost_per_mm3);
    any_raw_stock_ = any_raw_stock_ || prim.raw_stock;
  }
  for (const AtomSpec& atom : p.atoms) volume_.push_back(atom.volume);
  for (int i = 0; i < int(p.primitives.size()); ++i) {
    const auto& atoms = p.primitives[std::size_t(i)].atoms.words();
    const auto& mask = additive(p, i) ? must_out : must_in_;
    std::vector<std::uint64_t> wrong(mask.size());
    for (std::size_t w = 0; w < mask.size(); ++w) wrong[w] = atoms[w] & mask[w];
    wrong_.push_back(std::move(wrong));
    if (!additive(p, i)) continue;
    for (std::size_t w = 0; w < atoms.size(); ++w)
      for (std::uint64_t b = atoms[w]; b; b &= b - 1) adders_[w * 64 + std::size_t(std::countr_zero(b))].push_back(i);
  }
  for (auto& list : adders_)
    std::stable_sort(list.begin(), list.end(), [&](int x, int y) {
      return p.primitives[std::size_t(x)].cost_per_mm3 < p.primitives[std::size_t(y)].cost_per_mm3;
    });
}

// The cheapest rate of a deposit of atom `a` not used up, and which primitive that is.
double BackwardSearch::cheapest_rate(std::size_t a, const std::vector<std::uint8_t>& uses, int& by) const {
  for (const int i : adders_[a])
    if (uses[std::size_t(i)] < p_.max_uses) {
      by = i;
      return p_.primitives[std::size_t(i)].cost_per_mm3;
    }
  by = -1;
  return kInfinity;
}

// What atom `a` adds to the bound: deposited by its earliest toucher, then or before at no
// less than the cheapest rate left; undecided and must-in, deposited at least once.
double BackwardSearch::owed(std::size_t a, int earliest, double cheapest) const {
  const double volume = volume_[a];
  if (earliest >= 0)
    return adds_[std::size_t(earliest)] ? volume * std::min(rate_[std::size_t(earliest)], cheapest) : 0.0;
  return p_.atoms[a].must_in ? volume * cheapest : 0.0;
}

BackwardSearch::View BackwardSearch::view_of(int id) const {
  const std::size_t atoms = p_.atoms.size();
  View v{std::vector<int>(atoms, -1), std::vector<std::uint64_t>(must_in_.size(), 0),
         std::vector<std::uint64_t>(must_in_.size(), 0), std::vector<double>(atoms, 0),
         std::vector<double>(atoms, 0), std::vector<double>(atoms, kInfinity), std::vector<int>(atoms, -1), 0};
  for (int n = id; nodes_[std::size_t(n)].primitive >= 0; n = nodes_[std::size_t(n)].parent) {
    const int i = nodes_[std::size_t(n)].primitive;
    const auto& held = p_.primitives[std::size_t(i)].atoms.words();
    for (std::size_t w = 0; w < held.size(); ++w) {
      if (adds_[std::size_t(i)]) v.deposited[w] |= held[w] & ~v.decided[w];
      for (std::uint64_t b = held[w] & ~v.decided[w]; b; b &= b - 1) {
        const std::size_t a = w * 64 + std::size_t(std::countr_zero(b));
        v.earliest[a] = i;
        v.flip[a] = p_.primitives[std::size_t(i)].cost_per_mm3 * p_.atoms[a].volume;
      }
      v.decided[w] |= held[w];
    }
  }
  const auto& uses = nodes_[std::size_t(id)].uses;
  for (std::size_t a = 0; a < atoms; ++a) {
    v.cheapest[a] = cheapest_rate(a, uses, v.cheapest_by[a]);
    v.owed[a] = owed(a, v.earliest[a], v.cheapest[a]);
    v.bound += v.owed[a];
  }
  return v;
}

bool BackwardSearch::out_of_room() const {
  if (st_.expanded >= o_.max_expansions || std::int64_t(nodes_.size()) >= o_.max_states) return true;
  return deadline_ != Clock::time_point::max() && (st_.expanded & 255) == 0 && Clock::now() >= deadline_;
}

// Whether primitive `i` may come right before the suffix: not used up, in block order,
// and wrong on no atom the suffix leaves undecided.
bool BackwardSearch::may_precede(int i, const Node& node, const std::vector<std::uint64_t>& decided) const {
  if (node.uses[std::size_t(i)] >= p_.max_uses) return false;
  if (node.primitive >= 0 && o_.block_orders == BlockOrders::Cheapest && !in_block_order(p_, i, node.primitive))
    return false;
  const auto& wrong = wrong_[std::size_t(i)];
  for (std::size_t w = 0; w < wrong.size(); ++w)
    if (wrong[w] & ~decided[w]) return false;
  return true;
}

double BackwardSearch::start_cost(const View& v) const {
  double c = 0;
  for (std::size_t a = 0; a < v.earliest.size(); ++a)
    if (v.earliest[a] >= 0 && additive(p_, v.earliest[a])) c += v.flip[a];
  return c / p_.normaliser;
}

// Whether the suffix is a whole plan: it starts with a deposit (from stock when it must)
// and decides every must-in atom.
bool BackwardSearch::whole(const Node& node, const std::vector<std::uint64_t>& decided) const {
  if (node.primitive < 0 || !additive(p_, node.primitive)) return false;
  if (p_.start_from_stock && !p_.primitives[std::size_t(node.primitive)].raw_stock) return false;
  if (p_.primitives[std::size_t(node.primitive)].never_first) return false;
  for (std::size_t w = 0; w < decided.size(); ++w)
    if (must_in_[w] & ~decided[w]) return false;
  return true;
}

std::vector<std::uint64_t> BackwardSearch::key_of(const Node& node, const View& v) const {
  std::vector<std::uint64_t> key;
  append_uses(key, node.uses);
  key.push_back(std::uint64_t(std::int64_t(node.primitive)));
  for (std::size_t a = 0; a < v.earliest.size(); a += 4) {
    std::uint64_t packed = 0;
    for (std::size_t k = a; k < a + 4 && k < v.earliest.size(); ++k) packed = packed << 16 | std::uint16_t(v.earliest[k] + 1);
    key.push_back(packed);
  }
  return key;
}

// What a child costs: what the suffix's earliest touchers of i's atoms pay once i comes
// before them, plus the fixed costs between i and the suffix's first action.
double BackwardSearch::step_cost(int i, const Node& node, const View& v) const {
  double step = node.primitive >= 0 ? fixed_cost(p_, i, node.primitive) : 0;
  const bool adds = adds_[std::size_t(i)];
  const auto& held = p_.primitives[std::size_t(i)].atoms.words();
  for (std::size_t w = 0; w < held.size(); ++w) {
    // The earliest touchers of the other mode change the atom after i.
    const std::uint64_t other = adds ? v.decided[w] & ~v.deposited[w] : v.deposited[w];
    for (std::uint64_t b = held[w] & other; b; b &= b - 1) step += v.flip[w * 64 + std::size_t(std::countr_zero(b))];
  }
  return step / p_.normaliser;
}

// The child's bound, from the node's: only the shares of i's atoms change (their earliest
// toucher is i now, and i may have been their cheapest deposit left).
double BackwardSearch::child_bound(int i, const View& v, const std::vector<std::uint8_t>& uses) const {
  const bool used_up = uses[std::size_t(i)] >= p_.max_uses, adds = adds_[std::size_t(i)];
  const double rate = rate_[std::size_t(i)];
  double h = v.bound;
  const auto& held = p_.primitives[std::size_t(i)].atoms.words();
  for (std::size_t w = 0; w < held.size(); ++w)
    for (std::uint64_t b = held[w]; b; b &= b - 1) {
      const std::size_t a = w * 64 + std::size_t(std::countr_zero(b));
      h -= v.owed[a];
      if (!adds) continue;  // i removes it: no share
      int by = v.cheapest_by[a];
      const double cheapest = used_up && by == i ? cheapest_rate(a, uses, by) : v.cheapest[a];
      h += volume_[a] * std::min(rate, cheapest);
    }
  if (h == kInfinity || std::isnan(h)) return kInfinity;
  // Without a raw stock the plan starts with a deposit: a switch before i (a removal right
  // after a raw stock changes nothing, planner/problem/actions.hpp, fixed_cost).
  if (!adds && !any_raw_stock_) h += p_.fixed.mode_switch;
  return std::max(0.0, h) / p_.normaliser;
}

// Partial expansion: only the children with f up to `f` + window_ are stored, the others
// wait: the node goes back on the open list at the least f among them, and is expanded
// again when that comes up. Most children never would be, and the states they took were
// what stopped the search (max_states) before its expansions ran out.
void BackwardSearch::expand(int id, const View& v, double f) {
  Node& node = nodes_[std::size_t(id)];
  const bool again = node.upto > -kInfinity;
  if (!again && whole(node, v.decided)) {
    const double cost = node.g + start_cost(v);
    if (cost < prune_at_) open_.push({cost, cost, seq_++, id, true});
  }
  if (node.primitive >= 0 && p_.primitives[std::size_t(node.primitive)].raw_stock) return;  // raw stock only first
  const double upto = f + window_;
  double rest = kInfinity;
  for (int i = 0; i < int(p_.primitives.size()); ++i) {
    if (!may_precede(i, node, v.decided)) continue;
    Node child{id, i, node.g + step_cost(i, node, v), node.uses};
    ++child.uses[std::size_t(i)];
    const double h = child_bound(i, v, child.uses);
    if (h == kInfinity || child.g + h >= prune_at_) continue;
    const double child_f = child.g + o_.weight * h;
    if (again && child_f <= node.upto) continue;  // stored before
    if (child_f > upto) {
      rest = std::min(rest, child_f);
      continue;
    }
    ++st_.generated;
    nodes_.push_back(std::move(child));
    open_.push({child_f, nodes_.back().g, seq_++, int(nodes_.size()) - 1, false});
  }
  node.upto = upto;
  if (rest < kInfinity) open_.push({rest, node.g, seq_++, id, false});
}

Plan BackwardSearch::plan_of(int id) const {
  std::vector<int> sequence;
  for (int n = id; nodes_[std::size_t(n)].primitive >= 0; n = nodes_[std::size_t(n)].parent)
    sequence.push_back(nodes_[std::size_t(n)].primitive);
  Plan plan;
  if (!simulate(p_, sequence, plan)) plan.steps.clear();  // a step cannot be taken or changes nothing
  return plan;
}

std::vector<Plan> BackwardSearch::run(int wanted) {
  std::vector<Plan> plans;
  nodes_.push_back({-1, -1, 0, std::vector<std::uint8_t>(p_.primitives.size(), 0)});
  const double h0 = view_of(0).bound / p_.normaliser;
  if (h0 == kInfinity) return plans;
  window_ = kWindow * h0;
  open_.push({o_.weight * h0, 0, seq_++, 0, false});
  std::unordered_map<std::vector<std::uint64_t>, int, KeyHash> pops;
  while (!open_.empty() && int(plans.size()) < wanted) {
    const Entry e = open_.top();
    if (e.whole) {
      open_.pop();
      Plan plan = plan_of(e.node);
      if (plan.steps.empty()) {
        ++invalid_;  // as for a plan turned down: one more arrival per state may be of use
        continue;
      }
      const GoalFilter::Verdict verdict = goals_.judge(plan);
      if (verdict == GoalFilter::Take) plans.push_back(std::move(plan));
      if (verdict != GoalFilter::Stop) continue;
      limit_ = true;
      break;
    }
    const View v = view_of(e.node);
    if (e.node != 0 && !nodes_[std::size_t(e.node)].counted) {
      int& count = pops[key_of(nodes_[std::size_t(e.node)], v)];
      if (count >= o_.top_k + goals_.passed() + invalid_) {
        open_.pop();
        continue;
      }
      ++count;
      nodes_[std::size_t(e.node)].counted = true;
    }
    if (out_of_room()) {
      limit_ = true;
      break;
    }
    open_.pop();
    ++st_.expanded;
    expand(e.node, v, e.f);
  }
  frontier_ = open_.empty() ? kInfinity : open_.top().f;
  return plans;
}

}  // namespace hybridctl::planner::detail
