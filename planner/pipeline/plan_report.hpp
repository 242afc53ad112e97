#pragma once
// Writing a planning result: plan.json (docs/plan-format.md) with .vdb files of the
// design, each primitive and each plan's outcome, all in one output directory that
// appears whole or not at all.

#include <filesystem>
#include <string>

#include "plan/plan_file.hpp"
#include "planner/pipeline/planning.hpp"

namespace hybridctl::planner {

struct ReportSources {
  std::string part_path;     // as given (the summary prints it so)
  std::string machine_path;  // as given
  std::string machine_name;
  std::string machine_text;  // the machine file's YAML, which plan.json embeds
};

// The JSON document, as text, for a plan.json in `directory`: the paths it names are
// relative to that directory.
std::string plan_json(const PlanningResult& result, const ReportSources& sources, const std::filesystem::path& directory);

// A primitive's `capability` as plan.json records it: a file primitive's path relative to
// the plan's directory, any other as it is.
std::string primitive_capability(const Primitive& primitive, const std::filesystem::path& directory);

// The planning result as write_plan_directory(result, sources, directory) writes it and
// plan::read_plan_file(directory) reads it back, without the files: equal to what is read
// back, down to where each solid stores its voxels.
plan::PlanFile to_plan_file(const PlanningResult& result, const ReportSources& sources,
                            const std::filesystem::path& directory);

// Writes DIR/plan.json, DIR/design.vdb, DIR/primitives/Pn.vdb, DIR/plans/plan-k.vdb.
// DIR must not exist, be empty, or hold an earlier plan (it is replaced); anything else
// is refused with hybridctl::InputError rather than overwritten.
void write_plan_directory(const PlanningResult& result, const ReportSources& sources,
                          const std::filesystem::path& directory);

// The summary people read on the terminal. A refusal or UNDECIDED that can be said in
// shop words (PlanningResult::in_shop_words) is said so, its proof in atoms and regions left
// to plan.json unless `verbose`.
std::string plan_summary(const PlanningResult& result, const ReportSources& sources, bool verbose = false);

}  // namespace hybridctl::planner
