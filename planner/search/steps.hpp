#pragma once
// The plan search's steps, shared by the A* (search.cpp), the exhaustive enumerator and the
// reachability exploration (search_steps.cpp): what an action does to a state, what it
// costs beyond its volume, and which actions a plan may take where (C3, C4, max_uses).

#include <cstdint>
#include <set>
#include <vector>

#include "common/hash.hpp"
#include "planner/search/search.hpp"

namespace hybridctl::planner::detail {



// Whether primitive `i` may be taken: not used up, additive (and raw stock when the plan
// must start from stock) first, never raw stock later.
bool allowed(const PlanningProblem& p, int i, bool first, const std::vector<std::uint8_t>& uses);

// Whether `next` may follow `last` when one order per block is kept: within a block
// (same mode, tool and setup) raw stock first, then by cost per mm^3, then by index.
bool in_block_order(const PlanningProblem& p, int last, int next);

std::vector<int> sequence_of(const Plan& plan);

// What a plan does, step by step: each step's tool, setup and mode and the atoms it
// changes. Two plans with the same effect differ only in which primitive names a step
// (a whole-part deposit after a band was milled deposits what the band's deposit would).
std::vector<std::uint64_t> effect_of(const PlanningProblem& p, const std::vector<int>& sequence);


// Appends `uses` to a duplicate-detection key, eight counts a word.
void append_uses(std::vector<std::uint64_t>& key, const std::vector<std::uint8_t>& uses);

using KeyHash = WordsHash;

// What becomes of a plan a search reaches the goal with: returned, passed over (known
// already, doing what a returned one does, known to fail, or turned down by
// SearchOptions::accept), or the search stops (max_rejected plans turned down).
class GoalFilter {
 public:
  GoalFilter(const PlanningProblem& p, const SearchOptions& o, const std::set<std::vector<int>>& known, SearchStats& st);
  enum Verdict { Take, Pass, Stop };
  Verdict judge(const Plan& plan);
  // How many more arrivals at one state than top_k can be of use: one per plan passed over
  // since the search began.
  std::int64_t passed() const { return st_.rejected - rejected_before_ + same_effect_ + known_to_fail_; }

 private:
  const PlanningProblem& p_;
  const SearchOptions& o_;
  const std::set<std::vector<int>>& known_;
  SearchStats& st_;
  std::int64_t rejected_before_;
  std::set<std::vector<std::uint64_t>> effects_;  // of the plans returned or known (distinct_effects)
  std::int64_t same_effect_ = 0;  // goal plans passed over as doing what one returned does
  std::int64_t known_to_fail_ = 0;  // goal plans SearchOptions::known_to_fail passed over
};

}  // namespace hybridctl::planner::detail
