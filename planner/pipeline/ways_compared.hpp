#pragma once
// The part planned each way a shop could make it on one machine (docs/costs.md, "Hybrid
// against the other ways"): the hybrid plans as found, then the same machine without its
// heads (milled from stock) and without its cutting tools (deposited only), each with its
// best plan's machine time and money, as the plans are ranked, or why it has none.

#include <functional>
#include <string>
#include <vector>

#include "config/machine.hpp"
#include "planner/pipeline/planning.hpp"

namespace hybridctl::planner {

struct WayOfMaking {
  std::string name;            // "hybrid", "milled from stock", "deposited only"
  bool planned = false;        // a plan was offered
  std::string plan;            // its steps in words: "stock plate-12, 1 deposit, 2 removals"
  double minutes = 0;          // its machine time: its program's cycle time where known, else the estimate
  bool cycle_time = false;     // `minutes` is its program's cycle time
  double money = 0;            // its money, as the plans are ranked (the toolpaths' times where they ranked them)
  std::string why_not;         // no plan: the machine lacks the means, or the verdict in short
};

struct WaysCompared {
  std::vector<WayOfMaking> ways;  // hybrid first
  std::string currency;
};

// The way `result` (planned on `machine`) makes the part, and the two others, each planned
// by `plan_on` on a copy of `machine` without its heads or without its tools. A way the
// machine cannot take (no tool to mill with, no head to deposit with) is not planned.
WaysCompared compare_ways(const config::Machine& machine, const PlanningResult& result,
                          const std::function<PlanningResult(const config::Machine&)>& plan_on);

// "compare     ..." lines: one row per way, and what the cheapest saves against the others.
std::string ways_compared_text(const WaysCompared& compared);

}  // namespace hybridctl::planner
