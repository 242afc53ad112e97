#pragma once
// Raw stocks proven before the search to start no plan, or to start one (docs/search.md,
// "Each raw stock proven on its own"). A raw stock costs nothing, so the search's bound
// prices the design at nothing while a plan may still start from one: on a part a cutter
// cannot make to the tolerance (a round bore on a grid finer than the tolerance allows,
// say), every order of removals after the block looks cheap and is tried, and the
// exact search runs to its limit. The proof from a few atoms (planner/search/core_proof.hpp), on
// the problem with only that stock to start from, settles in a moment whether any plan
// does: a stock so proven is marked `never_first` and is in no plan; otherwise the proof's
// replay is a plan from that stock, which the search judges with the other seeds (on the
// tube on a plate at a tolerance under a voxel: the block milled to the plate and the tube
// deposited, cheaper than the proof of the whole problem found).
//
//   std::vector<StartProof> out = prove_stock_starts(problem, limits);

#include <cstdint>
#include <vector>

#include "planner/search/core_proof.hpp"
#include "planner/search/search.hpp"

namespace hybridctl::planner {

struct StartProof {
  int primitive = -1;  // the raw stock, an index into the problem's primitives
  CoreProof proof;     // on the problem with only it to start from
};

// Proves, raw stock by raw stock, whether a plan of `problem` starts from it, and marks
// those that start none `never_first`, unless no start would be left: a problem with no
// plan at all is left to the proof of the whole problem, which names the atoms. As that
// proof does, it takes learned corrections as they are. Empty when the problem has at most
// one possible start (the proof of the whole problem is then the same).
std::vector<StartProof> prove_stock_starts(PlanningProblem& problem, const CoreProofLimits& limits);

// The plans the proofs replayed (stocks that start one), as the search's seeds.
std::vector<std::vector<int>> start_seeds(const std::vector<StartProof>& starts);

}  // namespace hybridctl::planner
