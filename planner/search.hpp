#pragma once
// Plan search (paper section 7) on the symbolic problem: atoms with volumes and
// classes, primitives as sets of atoms. A state is the set of atoms present; an
// additive action unites its primitive's atoms with it, a subtractive one removes
// them. Plans obey C1-C4: a chain of actions (C1), AM as union and SM as intersection
// with the complement (C2), the first action additive (C3), raw stock only first (C4).

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "config/primitive_kind.hpp"
#include "planner/atom_set.hpp"

namespace hybridctl::planner {

using config::Mode;

struct AtomSpec {
  double volume = 0;  // mm^3
  bool must_in = false;
  bool must_out = false;  // both false: free either way
};

// What carries the first layer of an additive primitive, the one its build plate carries
// when the plan starts with it. Later in a plan the plate is not there: material already
// present must lie near under or beside that layer (planner/deposit_reach.hpp).
struct DepositFooting {
  enum Kind : std::uint8_t { None, OnPlate, NeedsCarrier };  // per atom
  std::vector<Kind> kind;
  AtomRelation carriers;  // per NeedsCarrier atom: the atoms that may carry it
};

struct PrimitiveSpec {
  std::string name;
  Mode mode = Mode::Additive;
  bool raw_stock = false;
  double cost_per_mm3 = 1.0;
  AtomSet atoms;          // the atoms inside the primitive
  std::string tool;       // tool or head identity, for tool-change costs
  std::string setup;      // setup name, for setup-change costs
  // The part is re-clamped by hand for this setup: a change into or out of it costs
  // FixedCosts::refixture instead of setup_change.
  bool refixture = false;
  // Additive only: for each atom, the atoms that, present, put part of it out of the head's
  // reach (planner/deposit_reach.hpp). The action cannot be taken in a state that holds one
  // of them over an atom it would deposit. Null: nothing limits it.
  std::shared_ptr<const AtomRelation> blocked_by;
  // Additive only: in a state that holds material, an atom of the first layer it would
  // deposit needs a carrier present; null: nothing limits it.
  std::shared_ptr<const DepositFooting> footing;
  // Atoms the action does not change once the plan has begun (in a state that holds
  // material), as executed candidates showed (planner/shortfall.hpp); empty: none.
  AtomSet falls_short;
  // Proven that no plan starts with it (planner/start_proofs.hpp): never a first action.
  // A raw stock so marked is in no plan at all.
  bool never_first = false;
};

// What changing between two consecutive actions costs (in the problem's cost units, before
// the normaliser): another tool or head, another setup (refixture when the operator
// re-clamps the part for one of the two setups), the other mode (milling <-> deposition).
struct FixedCosts {
  double tool_change = 0;
  double setup_change = 0;
  double mode_switch = 0;
  double refixture = 0;
};

struct PlanningProblem {
  std::vector<AtomSpec> atoms;
  std::vector<PrimitiveSpec> primitives;
  FixedCosts fixed;
  // Costs are divided by this volume (the design's bounding box, mm^3) so that plans of
  // different parts compare; 1 leaves them in cost units.
  double normaliser = 1.0;
  int max_uses = 1;  // how often one primitive may appear in a plan
  // Every plan begins with a raw stock (the shop's own stock was given: a repair starts from
  // the worn part, not from an empty plate).
  bool start_from_stock = false;
};

struct PlanStep {
  int primitive = -1;
  double volume = 0;  // mm^3 really deposited or removed in this state
  double cost = 0;    // normalised, including fixed costs incurred by this step
};

struct Plan {
  std::vector<PlanStep> steps;
  double cost = 0;  // normalised total
  AtomSet final_state;
  // Proven: cost <= (1 + gap) x the cheapest accepted plan's cost. 0 for a plan proven
  // optimal; for the k-th of k plans found in cost order by the exact search, how much
  // dearer it is than the first.
  double gap = 0;
  bool exact = true;  // proven to be the rank-th cheapest accepted plan
  bool built = false;  // built step by step (planner/search_greedy.hpp), not found by a search
  bool replayed = false;  // the proof's replay (SearchOptions::seeds), not found by a search
};

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
  // atoms they all treat alike merged (planner/search_reduce.hpp). The same plans at the
  // same costs; false searches the problem as given, for comparison.
  bool reduce = true;
  SearchDirection direction = SearchDirection::Auto;
  // Sequences found elsewhere that reach the goal (the proof from a few atoms replays one,
  // planner/core_proof.hpp, and so does each raw stock's, planner/start_proofs.hpp): when
  // the exact search stops at a limit, judged cheapest first before the plans built step
  // by step, as they are.
  std::vector<std::vector<int>> seeds;
};

// The k cheapest distinct accepted plans, cheapest first, by A* with the admissible
// bound of planner/search_bound.hpp. When the exact search stops at a limit (expansions,
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

// True when every must-in atom is in `state` and no must-out atom is.
bool is_goal(const PlanningProblem& problem, const AtomSet& state);

// The plan as the paper writes it, e.g. "(((P1 ∪ P2) − P3) − P4)".
std::string expression(const PlanningProblem& problem, const Plan& plan);

}  // namespace hybridctl::planner
