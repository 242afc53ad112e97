#pragma once
// A bundled part planned on the B-axis machine (setups +Z, +X, -X, +Y) with a search of one
// expansion: what the check and the proof before the search decide, for the refusal tests.

#include <string>

#include "config/machine_loader.hpp"
#include "geometry/mesh.hpp"
#include "planner/pipeline/planning.hpp"

namespace hybridctl::planner::testing {

inline const std::string kParts = HYBRIDCTL_SOURCE_DIR "/examples/parts/";
inline const std::string kMultitask = HYBRIDCTL_SOURCE_DIR "/examples/machines/multitask-b-axis.yaml";

inline PlanningResult proof_on_multitask(const std::string& part) {
  const config::Machine machine = config::load_machine(kMultitask);
  PlanningOptions options;
  options.max_expansions = 1;  // the proof decides before any search
  return plan_part(geometry::read_stl(kParts + part + ".stl"), part, machine, options);
}

}  // namespace hybridctl::planner::testing
