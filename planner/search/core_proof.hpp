#pragma once
// A proof that no plan exists, from a few atoms (docs/search.md, "No plan: a proof from a
// few atoms"). Projected on a set S of atoms, a plan's states are its states' members in S:
// an action changes in S exactly what it changes there in the whole problem, and whether
// it may be taken depends on atoms outside S only through what blocks a head and what
// carries a first layer. Taking the atoms outside S as never in the way and always there to
// carry gives a relaxation: every plan of the whole problem is, projected, a plan of the
// small one that gets every atom of S right. When breadth first search over the 2^|S|
// projected states finds none, no plan exists.
//
// S is found by refinement: a projected plan is replayed on the whole problem, and where
// it goes wrong (a deposit out of reach, a first layer with nothing under it, atoms wrong
// at the end) the atoms that show it join S. A replay that reaches the goal is a plan.

#include <atomic>
#include <cstdint>
#include <vector>

#include "planner/search/search.hpp"

namespace hybridctl::planner {

inline constexpr int kCoreWords = 8;  // S is at most 64 x this many atoms

// The budget of the proof `plan` runs beside the search when the one before it stopped at
// its budget: about 20-30 s and at most about 1 GB (no bundled part needs it).
inline constexpr std::int64_t kLongerProofStates = 24'000'000;

struct CoreProofLimits {
  int max_atoms = 64 * kCoreWords;     // S is at most this big
  int atoms_per_round = 1;             // wrong atoms of a replay's end state that join S
  std::int64_t max_states = 4'000'000;  // projected states reached, summed over the rounds
  // Once proven, S is made minimal (no atom of it can go) within this many more projected
  // states; 0 keeps S as the refinement left it.
  std::int64_t minimise_states = 2'000'000;
  // When set, asked every few thousand states: true gives up (Unknown), e.g. when a search
  // running beside the proof has found plans.
  const std::atomic<bool>* stop = nullptr;
};

// A quarter of the budget, for proofs that may run several in a row (a corrected
// problem's, each raw stock's): about a second at most.
inline CoreProofLimits quick_proof_limits() {
  CoreProofLimits l;
  l.max_states /= 4;
  l.minimise_states /= 4;
  return l;
}

struct CoreProof {
  enum class Outcome { Proven, Feasible, Unknown };
  Outcome outcome = Outcome::Unknown;
  // Proven: the atoms that no sequence of the primitives gets right together (S, sorted;
  // each joined it to refute a projected plan, and each is needed: without any one of them
  // some projected plan gets the others right, unless `minimise_states` ran out first).
  std::vector<int> core;
  std::vector<AtomSet> groups;  // Proven: the carrier groups S looked through (docs/search.md)
  // Feasible: primitives, in order, that make the whole goal (each used at most max_uses
  // times). Unknown: the limits were reached, or a projected plan's failure named no atom;
  // or a replay made the goal using a primitive more than max_uses times: then `sequence`
  // is that replay, and `reuse_needed` the most times it uses one primitive.
  std::vector<int> sequence;
  int reuse_needed = 0;
  // Why atoms joined S: a replayed deposit out of the head's reach, a first layer with
  // nothing under it, or atoms wrong at the end of a replayed plan; how many for each.
  enum class Why { OutOfReach, NothingUnder, WrongAtTheEnd };
  int joined[3] = {0, 0, 0};
  int rounds = 0;             // projections searched
  std::int64_t states = 0;    // projected states reached, over the rounds
  // Proven: the atoms S had when the refinement proved it, before it was made minimal,
  // and the projected states that took (not in `states`).
  int found = 0;
  std::int64_t minimising_states = 0;
};

// Air a raw stock holds that every removal holding it cuts design that must be made with
// it (or that no removal holds): it is cleared only by cutting the part, which must then be
// made again. A closed channel, or a corner no cutter reaches past the part's other walls:
// what a proof is about, where there is such an atom; the verdict names it first.
bool cleared_only_by_cutting(const PlanningProblem& problem, int atom);

// Whether the projection on `atoms`, looking through `groups` of carriers as the proof does,
// has no plan that gets every one of them right: then no plan of `problem` exists. False
// as well when that search passes `max_states`.
bool projection_refutes(const PlanningProblem& problem, const std::vector<int>& atoms,
                        const std::vector<AtomSet>& groups, std::int64_t max_states = 4'000'000);

// `problem`'s learned shortfalls are taken as they are: a proof on a problem with learned
// corrections proves only that problem infeasible.
CoreProof prove_by_core(const PlanningProblem& problem, const CoreProofLimits& limits = {});

}  // namespace hybridctl::planner
