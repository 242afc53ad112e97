#pragma once
// Plan search (paper section 7) on the symbolic problem (planner/problem/problem.hpp):
// the k cheapest plans by A* with an admissible bound, weighted A* and plans built step by
// step past its limits, each with its proven gap; the exhaustive enumerator and the
// reachability exploration that prove what the search cannot.

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "planner/problem/actions.hpp"
#include "planner/problem/problem.hpp"

namespace hybridctl::planner {

struct SearchStats {
  std::int64_t expanded = 0;
  std::int64_t generated = 0;
  bool exhausted = false;  // the search space ran out before k plans were found
  bool limit_reached = false;  // the exact search stopped at a limit before k plans
  double weight = 1.0;  // of the last search that produced plans (1: exact A*)
  std::int64_t rejected = 0;  // goal plans `SearchOptions::accept` turned down
  std::int64_t known_to_fail = 0;  // goal plans `SearchOptions::known_to_fail` passed over
  bool interrupted = false;  // SearchOptions::interrupt stopped it after a plan was turned down
  // Proven lower bound on the cheapest accepted plan's cost (normalised): its cost when
  // the exact search found it, else the least f = g + h left on the exact search's open
  // list when it stopped (no plan it did not reach can cost less).
  double lower_bound = 0;
  double seconds = 0;  // wall time of the whole search

  // A later round of the same job added to this one (planner/pipeline/search_phase.cpp):
  // counts and seconds add up; whether the space ran out or a limit stopped it, the weight
  // and the lower bound are the later round's, which searched the corrected problem.
  // `interrupted` stays this one's: it is the caller's to act on, round by round.
  SearchStats& operator+=(const SearchStats& later) {
    expanded += later.expanded;
    generated += later.generated;
    rejected += later.rejected;
    known_to_fail += later.known_to_fail;
    seconds += later.seconds;
    exhausted = later.exhausted;
    limit_reached = later.limit_reached;
    weight = later.weight;
    lower_bound = later.lower_bound;
    return *this;
  }
};

// Which orders of consecutive actions of one block (same mode, tool and setup) the search
// tells apart. Within a block the fixed costs do not depend on the order, and the
// cheapest order is by cost per mm^3 (each atom is paid at the rate of the first action
// that changes it), so keeping only that order loses no optimum; plans that differ only
// in such an order are then not listed as different plans.
enum class BlockOrders { Every, Cheapest };

// Which way the search builds plans (docs/search.md): from the empty state forwards, or
// from the goal backwards, a primitive put before a partial plan only when it gets no atom
// wrong that the rest leaves undecided. Auto: backwards when every atom is must-in or
// must-out and no primitive's reach or footing depends on the material present (blocked_by,
// footing: forward search knows it step by step, backward search only of whole plans);
// forwards otherwise.
enum class SearchDirection { Auto, Forward, Backward };

struct SearchOptions {
  SearchOptions() = default;
  // The plans wanted and the expansions each search may take; the rest at their defaults.
  SearchOptions(int plans, std::int64_t expansions = 5'000'000) : top_k(plans), max_expansions(expansions) {}

  int top_k = 5;
  std::int64_t max_expansions = 5'000'000;
  // Memory bound: the search stops (limit_reached) once it holds this many states. At a
  // few hundred bytes each, the default stays near 1 GB even with thousands of atoms.
  std::int64_t max_states = 3'000'000;
  // f = g + weight * h. 1 is A*: plans come cheapest first and the first is optimal. A
  // weight w > 1 (weighted A*) finds plans faster whose cost is at most w times the
  // optimum; the planner falls back to it when the exact search hits its limits.
  double weight = 1.0;
  // When set, every plan that reaches the goal is offered to it, cheapest first; only
  // plans it accepts are returned and count towards top_k, and the search goes on past
  // the rest (the validation of plans by execution keeps its reasons itself). At most
  // `max_rejected` plans are turned down before the search stops with limit_reached.
  std::function<bool(const Plan&)> accept;
  std::int64_t max_rejected = 50;
  // When set, asked before `accept`: a plan it names is passed over without being offered
  // and without counting against max_rejected (one that begins with the actions a plan
  // turned down failed in: execution depends only on the actions before, so it fails the
  // same way).
  std::function<bool(const Plan&)> known_to_fail;
  // When set, asked after `accept` turned a plan down: true stops the whole search there
  // (SearchStats::interrupted), weighted searches included, so that the caller may search
  // again on a problem it corrected from what the rejection showed.
  std::function<bool()> interrupt;
  BlockOrders block_orders = BlockOrders::Every;
  // Plans that do the same thing step by step (each step's tool, setup, mode and the atoms
  // it changes) are one plan to a shop: keep only the first, the cheapest, of them.
  bool distinct_effects = false;
  // Wall-clock budget of the whole search in seconds (0: none). When the exact search has
  // not finished in half of it, weighted A* finds plans in the rest, each with its proven
  // gap. A budget makes the result depend on the machine's speed; the expansion and state
  // limits do not.
  double time_limit = 0;
  // Search the problem reduced to the primitives that can take part in a plan, with the
  // atoms they all treat alike merged (planner/search/reduce.hpp). The same plans at the
  // same costs; false searches the problem as given, for comparison.
  bool reduce = true;
  SearchDirection direction = SearchDirection::Auto;
  // Sequences found elsewhere that reach the goal (the proof from a few atoms replays one,
  // planner/search/core_proof.hpp, and so does each raw stock's, planner/search/start_proofs.hpp): when
  // the exact search stops at a limit, judged cheapest first before the plans built step
  // by step, as they are.
  std::vector<std::vector<int>> seeds;
};

// The k cheapest distinct accepted plans, cheapest first, by A* with the admissible
// bound of planner/search/bound.hpp. When the exact search stops at a limit (expansions,
// states, half the time budget) before k plans, seeds and plans built step by step, then
// weighted A* fill the list: w = 50 first (nearly greedy: a plan soon), then w = 5 and
// w = 2 for cheaper ones, each within the same limits (a quarter of the expansions once
// there is a plan) and skipping what cannot beat the plans kept; the cheapest
// distinct plans found are kept, each with its proven gap against the exact search's
// lower bound (Plan::gap, Plan::exact, SearchStats::lower_bound). With options.weight > 1
// only that weighted search runs.
std::vector<Plan> find_plans(const PlanningProblem& problem, const SearchOptions& options = {},
                             SearchStats* stats = nullptr);

// Every plan, by depth-first enumeration, cheapest first, at most `limit` kept. The
// oracle for find_plans on small problems.
std::vector<Plan> enumerate_plans(const PlanningProblem& problem, std::size_t limit = SIZE_MAX);

// Which states the primitives can reach at all, costs aside and each primitive any number
// of times (a relaxation of max_uses): when none of them is a goal, no plan exists. Breadth
// first from the empty state, at most `max_states` states.
struct Reachability {
  bool complete = false;  // every reachable state was visited
  bool goal = false;      // a goal state is reachable (the exploration stops there)
  std::int64_t states = 0;
  // A reachable state with the least volume wrong (must-in atoms missing plus must-out
  // atoms present), and that volume in mm^3.
  AtomSet nearest;
  double wrong_volume = 0;
};
Reachability explore_reachable(const PlanningProblem& problem, std::int64_t max_states = 200'000);


}  // namespace hybridctl::planner
