#include "planner/search/start_proofs.hpp"

#include <algorithm>

namespace hybridctl::planner {

std::vector<StartProof> prove_stock_starts(PlanningProblem& problem, const CoreProofLimits& limits) {
  std::vector<StartProof> out;
  int starts = 0;
  for (const PrimitiveSpec& p : problem.primitives)
    starts += !p.never_first && p.mode == Mode::Additive && (p.raw_stock || !problem.start_from_stock);
  if (starts < 2) return out;
  for (std::size_t s = 0; s < problem.primitives.size(); ++s) {
    if (!problem.primitives[s].raw_stock || problem.primitives[s].never_first) continue;
    PlanningProblem only = problem;  // with only this stock to start from
    for (std::size_t i = 0; i < only.primitives.size(); ++i)
      if (i != s) only.primitives[i].never_first = true;
    out.push_back({int(s), prove_by_core(only, limits)});
  }
  const auto proven = [](const StartProof& s) { return s.proof.outcome == CoreProof::Outcome::Proven; };
  const auto ruled_out = std::count_if(out.begin(), out.end(), proven);
  if (ruled_out == starts) return out;
  for (const StartProof& s : out)
    if (proven(s)) problem.primitives[std::size_t(s.primitive)].never_first = true;
  return out;
}

std::vector<std::vector<int>> start_seeds(const std::vector<StartProof>& starts) {
  std::vector<std::vector<int>> out;
  for (const StartProof& s : starts)
    if (s.proof.outcome == CoreProof::Outcome::Feasible) out.push_back(s.proof.sequence);
  return out;
}

}  // namespace hybridctl::planner
