#pragma once
// What `hybridctl export` does, shared with `hybridctl plan --export`.

#include <string>

#include "plan/plan_file.hpp"

namespace hybridctl::cli {

struct ExportRequest {
  std::string plan;     // plan.json or its directory
  std::string output;   // directory for the programs
  int rank = 1;         // which plan
  std::string dialect;  // empty: the machine file's
  std::string machine;  // empty: the machine plan.json embeds (plan/plan_machine.hpp)
  bool machine_override = false;  // take `machine` even when it is another machine
  std::string arcs = "fit";       // "fit": circular runs of feed moves as G2/G3; "lines": G1 only
};

int export_plan_programs(const ExportRequest& request);
// The same for a plan already in memory (request.plan names it in messages).
int export_plan_programs(const plan::PlanFile& file, const ExportRequest& request);

}  // namespace hybridctl::cli
