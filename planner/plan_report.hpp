#pragma once
// Writing a planning result: plan.json (docs/plan-format.md) with .vdb files of the
// design, each primitive and each plan's outcome, all in one output directory that
// appears whole or not at all.

#include <filesystem>
#include <string>

#include "planner/planning.hpp"

namespace hybridctl::planner {

inline constexpr int kPlanFormatVersion = 1;

struct ReportSources {
  std::string part_path;
  std::string machine_path;
  std::string machine_name;
};

// The JSON document, as text.
std::string plan_json(const PlanningResult& result, const ReportSources& sources);

// Writes DIR/plan.json, DIR/design.vdb, DIR/primitives/Pn.vdb, DIR/plans/plan-k.vdb.
// DIR must not exist, be empty, or hold an earlier plan (it is replaced); anything else
// is refused with hybridctl::InputError rather than overwritten.
void write_plan_directory(const PlanningResult& result, const ReportSources& sources,
                          const std::filesystem::path& directory);

// The summary people read on the terminal.
std::string plan_summary(const PlanningResult& result, const ReportSources& sources);

}  // namespace hybridctl::planner
