#pragma once
// The plan search from the goal backwards (docs/search.md). Read backwards, a plan's last
// action decides the final status of every atom it holds, the one before it of the atoms
// the last does not hold, and so on: a partial plan is a suffix, and a primitive may be
// put before it only when it gets no atom wrong that the suffix leaves undecided. Few
// primitives qualify while little is decided, which is what makes the search narrow
// where forward search has every primitive to try and a bound that cannot tell which
// lead anywhere.
//
// The costs: an atom is paid for at each action that changes it, at that action's rate.
// Whether an action changes an atom depends on the toucher before it: putting a primitive
// before a suffix settles, for each atom it holds, what the suffix's earliest toucher of
// it pays. What the earliest touchers pay when nothing comes before them (a deposit from
// the empty state) is paid when the suffix is taken as the whole plan. A suffix's state
// for duplicate detection is therefore its uses, its first action (fixed costs, block
// order) and each atom's earliest toucher.
//
// The bound: an atom whose earliest toucher deposits it is deposited at that rate or, by
// an earlier deposit, at no less than the cheapest rate left; an undecided must-in atom is
// deposited at least once at that rate; a suffix that starts with a removal needs a mode
// switch before it. It is consistent. Reach (blocked_by) and footing need the state before
// an action, which only the whole plan gives: plans are replayed forwards when complete and
// passed over when a step cannot be taken, changes nothing or comes after the goal.
//
// Expansion is partial (expand()): a suffix stores only its children with f near its own,
// and comes up again for the rest, which keeps the states stored far below max_states.

#include <chrono>
#include <cstdint>
#include <deque>
#include <limits>
#include <queue>
#include <set>
#include <vector>

#include "planner/search/search.hpp"
#include "planner/search/steps.hpp"

namespace hybridctl::planner::detail {

class BackwardSearch {
 public:
  using Clock = std::chrono::steady_clock;
  BackwardSearch(const PlanningProblem& p, const SearchOptions& o, Clock::time_point deadline,
                 const std::set<std::vector<int>>& known, SearchStats& st, double prune_at);

  // Accepted plans not in `known`, cheapest first (by f), at most `wanted`.
  std::vector<Plan> run(int wanted);
  // No plan the search did not return costs less than this (meaningful for weight 1).
  double frontier() const { return frontier_; }
  bool stopped_at_limit() const { return limit_; }

 private:
  struct Node {
    int parent = -1;     // the node of the rest of the suffix
    int primitive = -1;  // the suffix's first action
    double g = 0;        // normalised: what the suffix's actions pay, but for its earliest touchers
    std::vector<std::uint8_t> uses;
    double upto = -std::numeric_limits<double>::infinity();  // children with f up to this are stored
    bool counted = false;  // its arrival at its state is counted (duplicate detection)
  };
  struct Entry {
    double f, g;
    std::int64_t seq;
    int node;
    bool whole;  // the suffix taken as the whole plan
  };
  struct Worse {
    bool operator()(const Entry& a, const Entry& b) const {
      if (a.f != b.f) return a.f > b.f;
      if (a.whole != b.whole) return b.whole;  // plans first on ties
      if (a.g != b.g) return a.g < b.g;
      return a.seq > b.seq;
    }
  };
  // A suffix seen atom by atom, from its node: what a child is costed and bounded from.
  struct View {
    std::vector<int> earliest;  // per atom: the suffix's earliest toucher, -1 undecided
    std::vector<std::uint64_t> decided;
    std::vector<std::uint64_t> deposited;  // the decided atoms whose earliest toucher deposits them
    std::vector<double> flip;     // per decided atom: what its earliest toucher pays if it changes it
    std::vector<double> owed;     // per atom: its share of the bound
    std::vector<double> cheapest;  // per atom: the cheapest rate of a deposit not used up
    std::vector<int> cheapest_by;  // and which primitive that is
    double bound = 0;              // the sum of `owed`, not normalised
  };
  View view_of(int id) const;
  double owed(std::size_t a, int earliest, double cheapest) const;
  double cheapest_rate(std::size_t a, const std::vector<std::uint8_t>& uses, int& by) const;
  bool out_of_room() const;
  bool may_precede(int i, const Node& node, const std::vector<std::uint64_t>& decided) const;
  bool whole(const Node& node, const std::vector<std::uint64_t>& decided) const;
  double start_cost(const View& v) const;
  double step_cost(int i, const Node& node, const View& v) const;
  double child_bound(int i, const View& v, const std::vector<std::uint8_t>& uses) const;
  void expand(int id, const View& v, double f);
  std::vector<std::uint64_t> key_of(const Node& node, const View& v) const;
  Plan plan_of(int id) const;

  const PlanningProblem& p_;
  const SearchOptions& o_;
  Clock::time_point deadline_;
  GoalFilter goals_;
  SearchStats& st_;
  double prune_at_;
  std::vector<std::uint64_t> must_in_;             // mask
  std::vector<std::vector<std::uint64_t>> wrong_;  // per primitive: the atoms its mode gets wrong
  std::vector<std::vector<int>> adders_;           // per atom, cheapest first
  std::vector<char> adds_;                         // per primitive: additive
  bool any_raw_stock_ = false;                     // some primitive is a raw stock
  std::vector<double> rate_, volume_;              // per primitive, per atom
  std::deque<Node> nodes_;
  std::priority_queue<Entry, std::vector<Entry>, Worse> open_;
  std::int64_t seq_ = 0;
  double frontier_ = std::numeric_limits<double>::infinity();
  bool limit_ = false;
  std::int64_t invalid_ = 0;  // whole plans passed over as not valid forwards
  double window_ = 0;         // partial expansion: see expand()
};

}  // namespace hybridctl::planner::detail
