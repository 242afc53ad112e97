#pragma once
// The admissible lower bound of the plan search: what any completion of a partial plan
// must still pay, from its state, the primitives it may still use and its last action.
// Its parts, on disjoint shares of the cost so that they add:
//  - atoms: a missing must-in atom is deposited at least once, a present must-out atom
//    removed at least once, each at the cheapest rate of a primitive still allowed that
//    holds it (the classic bound), and the must-in atom at the cheapest rate of one that
//    may lay it last (lays_last: a block's design cut to clear what only the cut reaches
//    is deposited again by a head that does not fill it in);
//  - side effects: the primitive that deposits the dearest missing must-in atom also
//    deposits its absent other atoms (and any must-out one among them must then be
//    removed); likewise the removal of a must-out atom takes present other atoms with it
//    (a must-in one must come back);
//  - removals with the design they cut: a removal that cuts design present is followed by a
//    deposit of it, so each must-out atom present is priced among the removals whose
//    design share is at most a threshold, plus the threshold, least over thresholds (this
//    and the removal parts of the two above bound one share: the larger counts);
//  - design laid again (relays, beside the sum of the two shares above and the side
//    effects, not in it): each must-in atom missing, and the design the dearest removal
//    cuts, is laid last either by an adder under a rate threshold, whose use lays its
//    side effects (an overfilling head's waste, absent now, laid and cut again), or by
//    one at or above it: the cheaper of the two counts (a ring on a plate milled from a
//    block: each removal that clears the bore cuts part of the ring, laid again at the
//    exact head's rate or with the wire-arc's overfill);
//  - fixed costs: a mode switch when the other mode is still needed (two when every
//    additive primitive left holds a must-out atom and the plan is removing now), a tool
//    change per tool that some atom can only be changed by, other than the current one,
//    and likewise per setup (at the least a change into that setup costs: a refixture
//    when the part is re-clamped for it).
// Only primitives some suffix of a plan can hold count as still allowed
// (planner/search/reduce.hpp: SuffixClosure), which makes every part larger and tells
// dead ends: a wrong atom none of them can fix.
// The bound is admissible, and consistent (it never falls by more than an action costs)
// except across a deposit of a must-in atom that is not its last (lays_last): that drops
// the atom's charge at the rate of its last deposit, and the charge comes back only partly,
// through the removals of what the deposit laid with it. The search needs admissibility
// alone: its duplicate detection compares arrivals at one state, uses and last action,
// which have one bound, so they are taken in the order of their cost either way.
// tests/planner/search/search_test.cpp checks both properties against the exhaustive enumerator.

#include <cstdint>
#include <vector>

#include "planner/search/search.hpp"
#include "planner/search/reduce.hpp"

namespace hybridctl::planner {

class LowerBound {
 public:
  explicit LowerBound(const PlanningProblem& problem);

  // The bound in normalised cost units, +infinity when the goal is out of reach (a
  // must-in atom no allowed primitive deposits, a must-out atom none removes).
  // `uses[i]`: how often primitive i has been used; `last`: the previous action, -1 at
  // the start (then raw stocks are allowed and the first action has no fixed cost).
  double operator()(const AtomSet& state, const std::vector<std::uint8_t>& uses, int last) const;

  // Only the atom part and the fixed costs: cheaper, never above operator().
  double quick(const AtomSet& state, const std::vector<std::uint8_t>& uses, int last) const;
  // The same with `within` taken as the primitives still allowed: any superset of usable()
  // (a parent's, less what the child used up) keeps it a bound, and saves the closure.
  double quick(const AtomSet& state, const std::vector<bool>& within, int last) const;

  // Whether primitive i may be the last to lay must-in atom a: it is not when it also lays
  // a must-out atom that every removal holding it takes `a` away with. The atom part
  // charges a missing must-in atom the cheapest rate of the primitives that may.
  bool lays_last(int i, int a) const;

  // The primitives a completion may still use: not used up, no raw stock after the first
  // action, and held by some suffix of a plan reaching the goal.
  std::vector<bool> usable(const std::vector<std::uint8_t>& uses, bool first) const;

 private:
  struct Rates;
  friend struct Rates;
  Rates rates(const std::vector<std::uint8_t>& uses, bool first) const;
  // Shares of the bound: what depositing and what removing still costs.
  struct AtomShares {
    double deposits = 0, removals = 0;
  };
  struct SideShares {
    double deposits = 0, removals = 0;
    std::vector<double> of;  // per primitive: what using it costs beyond the atom part
  };
  AtomShares atom_part(const AtomSet& state, const Rates& r) const;
  SideShares side_effects(const AtomSet& state, const Rates& r) const;
  // Per rate threshold: what laying must-in atoms last costs beyond the atom part's rate
  // (planner/search/bound.cpp: relays).
  struct Relay {
    double threshold = 0;
    double cheap_side = 0;      // the least side effect of an allowed adder under the threshold
    std::vector<double> extra;  // per last-adder list, per mm³ (relay_extras)
  };
  std::vector<Relay> relays(const Rates& r, const std::vector<double>& side) const;
  void relay_extras(const Rates& r, Relay& relay) const;
  // The removals' share two ways: with the design they cut at the atom part's rates, and
  // with what laying that design and the missing design last costs beyond them (0 where
  // it cannot exceed the other shares' sum).
  struct DesignCut {
    double plain = 0, relaid = 0;
  };
  DesignCut removals_with_design_cut(const AtomSet& state, const Rates& r, const SideShares& side,
                                     const AtomShares& atoms) const;
  double relaid_share(const AtomSet& state, const Rates& r, std::vector<Relay>& relay, const std::vector<int>& rank,
                      const std::vector<double>& base, std::size_t priced_from) const;
  double fixed_part(const AtomSet& state, const Rates& r, int last) const;
  void index_lists();
  void force(const AtomSet& state, const Rates& r, std::vector<bool>& tool_forced, std::vector<bool>& setup_forced) const;

  const PlanningProblem& p_;
  SuffixClosure closure_;
  int atoms_ = 0;
  std::vector<std::uint64_t> must_in_, must_out_;  // masks
  std::vector<std::vector<int>> adders_, removers_;  // per atom, cheapest first
  // The distinct lists among adders_ and removers_, and per atom which its lists are: many
  // atoms share one, and what the lists force is worked out once per list.
  std::vector<std::vector<int>> lists_;
  std::vector<int> adder_list_, remover_list_;
  // Per atom its list of the adders that can lay it last (planner/search/bound.cpp).
  std::vector<int> last_adder_list_;
  std::vector<bool> lays_some_last_;  // per primitive: on some must-in atom's last-adder list
  std::vector<int> last_lists_;       // the lists that are some must-in atom's last-adder list
  std::vector<double> thresholds_;    // the rates of the primitives that lay some design last
  std::vector<std::vector<int>> last_adders() const;
  // Per list the rate of its first (cheapest) member, and per primitive the lists it comes
  // first in: [0] with every primitive allowed, [1] with the raw stocks left out, as they
  // are after the first action (they cost nothing and lead most deposits' lists).
  struct Leaders {
    std::vector<double> rate;
    std::vector<std::vector<int>> led_by;
  };
  Leaders leaders_[2];
  // Bit masks over the primitives: per list its members, per tool (setup) id its primitives.
  std::vector<std::vector<std::uint64_t>> list_mask_, tool_mask_, setup_mask_;
  // Per list with a wrong atom in `state` (must-in missing: adders, or with `last` the
  // adders that can lay it last; must-out present: removers).
  std::vector<char> needed_lists(const AtomSet& state, bool last = false) const;
  // Per primitive, the sum over the supplier lists it is on (an atom is held by exactly the
  // primitives of its lists, so a sum over atoms per primitive is one per list, added up).
  std::vector<double> per_primitive(const std::vector<double>& per_list) const;
  std::vector<int> tool_id_, setup_id_;               // per primitive
  std::vector<double> setup_entry_;                   // per setup id: the least a change into it costs
  std::vector<bool> dirty_;  // an additive primitive holding a must-out atom
};

}  // namespace hybridctl::planner
