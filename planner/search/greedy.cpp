#include "planner/search/greedy.hpp"

#include <algorithm>
#include <bit>
#include <deque>
#include <limits>
#include <map>
#include <set>

#include "planner/search/steps.hpp"

namespace hybridctl::planner {
namespace {

using detail::allowed;

// Greedy runs in all: a plan per start, then variants; each run is a few dozen applications
// per step, so this keeps the whole at a fraction of a second on the B-axis machine's problems.
constexpr int kMaxRuns = 120;
constexpr int kMaxSteps = 64;

class Greedy {
 public:
  explicit Greedy(const PlanningProblem& p) : p_(p), words_(std::size_t((p.atoms.size() + 63) / 64)) {
    must_in_.assign(words_, 0);
    must_out_.assign(words_, 0);
    clearable_.assign(words_, 0);
    for (std::size_t a = 0; a < p.atoms.size(); ++a) {
      if (p.atoms[a].must_in) must_in_[a / 64] |= std::uint64_t{1} << (a % 64);
      if (p.atoms[a].must_out) must_out_[a / 64] |= std::uint64_t{1} << (a % 64);
    }
    // What removals that never cut the design clear.
    for (const PrimitiveSpec& prim : p.primitives) {
      if (prim.mode != Mode::Subtractive || touches(prim.atoms.words(), must_in_)) continue;
      for (std::size_t w = 0; w < words_; ++w) clearable_[w] |= prim.atoms.words()[w];
    }
  }

  // The plan from `start`, never using `banned`; empty when it gets stuck.
  std::vector<int> run(int start, const std::vector<bool>& banned) const {
    const int n = int(p_.primitives.size());
    std::vector<std::uint8_t> uses(std::size_t(n), 0);
    AtomSet state(int(p_.atoms.size())), next;
    double volume = 0;
    if (!allowed(p_, start, true, uses) || !apply(p_, state, start, next, volume, true)) return {};
    std::vector<int> sequence{start};
    ++uses[std::size_t(start)];
    state = std::move(next);
    for (int step = 0; step < kMaxSteps; ++step) {
      if (is_goal(p_, state)) return sequence;
      int best = pick(state, uses, banned, sequence.back(), Mode::Additive);
      if (best < 0) best = pick(state, uses, banned, sequence.back(), Mode::Subtractive);
      if (best < 0) return {};
      apply(p_, state, best, next, volume, false);
      state = std::move(next);
      ++uses[std::size_t(best)];
      sequence.push_back(best);
    }
    return {};
  }

 private:
  static bool touches(const std::vector<std::uint64_t>& a, const std::vector<std::uint64_t>& b) {
    for (std::size_t w = 0; w < a.size() && w < b.size(); ++w)
      if (a[w] & b[w]) return true;
    return false;
  }

  double volume_of(const std::vector<std::uint64_t>& bits) const {
    double v = 0;
    for (std::size_t w = 0; w < bits.size(); ++w)
      for (std::uint64_t b = bits[w]; b; b &= b - 1) v += p_.atoms[w * 64 + std::size_t(std::countr_zero(b))].volume;
    return v;
  }

  // The action of `mode` with the least cost per mm³ of atoms it puts right: a deposit of
  // missing design that lays nothing outside it no clean removal clears, or a removal of
  // material outside the design that spares the design present. -1 when there is none.
  int pick(const AtomSet& state, const std::vector<std::uint8_t>& uses, const std::vector<bool>& banned, int last,
           Mode mode) const {
    const auto& s = state.words();
    int best = -1;
    double best_score = std::numeric_limits<double>::infinity();
    std::vector<std::uint64_t> good(words_), bad(words_);
    for (int i = 0; i < int(p_.primitives.size()); ++i) {
      const PrimitiveSpec& prim = p_.primitives[std::size_t(i)];
      if (prim.mode != mode || banned[std::size_t(i)] || !allowed(p_, i, false, uses)) continue;
      AtomSet next;
      double volume = 0;
      if (!apply(p_, state, i, next, volume, false)) continue;
      const auto& n = next.words();
      bool wrong = false;
      for (std::size_t w = 0; w < words_; ++w) {
        if (mode == Mode::Additive) {
          const std::uint64_t laid = n[w] & ~s[w];
          good[w] = laid & must_in_[w];
          wrong = wrong || (laid & must_out_[w] & ~clearable_[w]);
        } else {
          const std::uint64_t cleared = s[w] & ~n[w];
          good[w] = cleared & must_out_[w];
          wrong = wrong || (cleared & must_in_[w]);
        }
      }
      if (wrong) continue;
      const double gain = volume_of(good);
      if (gain <= 0) continue;
      const double score = (prim.cost_per_mm3 * volume + fixed_cost(p_, last, i)) / gain;
      if (score < best_score) best_score = score, best = i;
    }
    return best;
  }

  const PlanningProblem& p_;
  std::size_t words_;
  std::vector<std::uint64_t> must_in_, must_out_, clearable_;
};

}  // namespace

std::vector<std::vector<int>> greedy_sequences(const PlanningProblem& p, std::size_t limit) {
  const int n = int(p.primitives.size());
  const Greedy greedy(p);
  std::map<std::vector<int>, double> found;  // sequence -> cost
  std::set<std::pair<int, std::vector<bool>>> tried;
  std::deque<std::pair<int, std::vector<bool>>> queue;
  const std::vector<std::uint8_t> none(std::size_t(n), 0);
  for (int i = 0; i < n; ++i)
    if (allowed(p, i, true, none)) queue.emplace_back(i, std::vector<bool>(std::size_t(n), false));
  int runs = 0;
  while (!queue.empty() && runs < kMaxRuns) {
    auto [start, banned] = std::move(queue.front());
    queue.pop_front();
    if (!tried.emplace(start, banned).second) continue;
    ++runs;
    const std::vector<int> sequence = greedy.run(start, banned);
    Plan plan;
    if (sequence.empty() || found.count(sequence) || !simulate(p, sequence, plan) ||
        !is_goal(p, plan.final_state))
      continue;
    found.emplace(sequence, plan.cost);
    // The runner-up choices: the same start without one of the actions taken.
    for (std::size_t k = 1; k < sequence.size(); ++k) {
      std::vector<bool> more = banned;
      more[std::size_t(sequence[k])] = true;
      queue.emplace_back(start, std::move(more));
    }
  }
  std::vector<std::pair<double, std::vector<int>>> by_cost;
  for (const auto& [sequence, cost] : found) by_cost.emplace_back(cost, sequence);
  std::stable_sort(by_cost.begin(), by_cost.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<std::vector<int>> out;
  for (auto& [cost, sequence] : by_cost) {
    if (out.size() >= limit) break;
    out.push_back(std::move(sequence));
  }
  return out;
}

}  // namespace hybridctl::planner
