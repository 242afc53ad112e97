#pragma once
// The symbolic planning problem (paper sections 6-7), the types every step of the planner
// shares: atoms with volumes and classes, primitives as sets of atoms, plans as sequences
// of actions. A state is the set of atoms present; an additive action unites its
// primitive's atoms with it, a subtractive one removes them (planner/problem/actions.hpp).
// Plans obey C1-C4: a chain of actions (C1), AM as union and SM as intersection with the
// complement (C2), the first action additive (C3), raw stock only first (C4).

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "config/primitive_kind.hpp"
#include "planner/problem/atom_set.hpp"

namespace hybridctl::planner {

using config::Mode;

struct AtomSpec {
  double volume = 0;  // mm^3
  bool must_in = false;
  bool must_out = false;  // both false: free either way
};

// What carries the first layer of an additive primitive, the one its build plate carries
// when the plan starts with it. Later in a plan the plate is not there: material already
// present must lie near under or beside that layer (planner/atoms/deposit_reach.hpp).
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
  // reach (planner/atoms/deposit_reach.hpp). The action cannot be taken in a state that holds one
  // of them over an atom it would deposit. Null: nothing limits it.
  std::shared_ptr<const AtomRelation> blocked_by;
  // Additive only: in a state that holds material, an atom of the first layer it would
  // deposit needs a carrier present; null: nothing limits it.
  std::shared_ptr<const DepositFooting> footing;
  // Atoms the action does not change once the plan has begun (in a state that holds
  // material), as executed candidates showed (planner/pipeline/shortfall.hpp); empty: none.
  AtomSet falls_short;
  // Proven that no plan starts with it (planner/search/start_proofs.hpp): never a first action.
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
  bool built = false;  // built step by step (planner/search/greedy.hpp), not found by a search
  bool replayed = false;  // the proof's replay (SearchOptions::seeds), not found by a search

  // Its primitives in order: what names a plan wherever plans are matched or looked up.
  std::vector<int> primitives() const {
    std::vector<int> s;
    for (const PlanStep& step : steps) s.push_back(step.primitive);
    return s;
  }
};

}  // namespace hybridctl::planner
