#include <cstdio>
#include <filesystem>
#include <memory>

#include "cli/commands.hpp"
#include "cli/memory_budget.hpp"
#include "cli/objective.hpp"
#include "cli/ranges.hpp"
#include "cli/export_run.hpp"
#include "cli/progress.hpp"
#include "cli/report_job.hpp"
#include "common/error.hpp"
#include "config/machine_loader.hpp"
#include "planner/pipeline/candidate_execution.hpp"
#include "planner/pipeline/plan_report.hpp"
#include "planner/pipeline/ways_compared.hpp"
#include "validation/plan_validator.hpp"
#include "verification/exact_deviation.hpp"
#include "gcode/post.hpp"

namespace hybridctl::cli {
namespace {

struct PlanArgs {
  std::string part;
  std::string machine;
  std::string output;
  std::string export_dir;
  std::string dialect;
  double voxel = 0;
  std::string memory_budget;
  double tolerance = -1;
  int top = 0;
  int reuse = 1;
  double search_time = 0;
  std::vector<std::string> primitive_files;
  std::vector<std::string> stock_files;
  bool no_validate = false;
  bool no_bands = false;
  bool no_fine_graining = false;
  bool no_filled = false;
  bool no_learning = false;
  std::string objective;
  int max_rejected = 200;
  bool report = false;
  bool compare = false;
  bool verbose = false;
};

planner::PrimitiveFile parse_primitive_argument(const std::string& arg) {
  const auto colon = arg.rfind(':');
  const std::string mode = colon == std::string::npos ? "" : arg.substr(colon + 1);
  if (mode != "am" && mode != "sm") {
    throw InputError("--primitive " + arg + ": expected FILE:am or FILE:sm (additive or subtractive)");
  }
  return {arg.substr(0, colon), mode == "am" ? config::Mode::Additive : config::Mode::Subtractive, 1.0};
}

int run_plan(const PlanArgs& args) {
  if (args.report && args.output.empty() && args.export_dir.empty())
    throw InputError("--report: the report is made from the plan directory: give -o DIR (or --export DIR)");
  const std::string machine_text = config::read_machine_text(args.machine);
  const config::Machine machine = gcode::parse_postable_machine(machine_text, args.machine);
  const geometry::TriangleMesh mesh = geometry::read_stl(args.part);
  // The options for planning on `on` (the machine file's, or a copy --compare plans on).
  const auto options_for = [&](const config::Machine& on) {
    planner::PlanningOptions options;
    options.voxel_size = args.voxel;
    options.memory_budget = memory_budget(args.memory_budget);
    options.tolerance = args.tolerance;
    options.top_k = args.top;
    options.max_uses = args.reuse;
    options.search_time = args.search_time;
    for (const std::string& p : args.primitive_files) options.extra_primitives.push_back(parse_primitive_argument(p));
    options.stock_files = args.stock_files;
    // Every plan offered is proven by execution first (validation/, docs/validation.md), and
    // the part it makes verified against the STL's real surface (docs/verification.md).
    if (!args.no_validate) {
      validation::ExecutionOptions proving;
      proving.surfaces = std::make_shared<verification::DesignSurfaces>(mesh, args.part);
      planner::validate_by_execution(options, validation::plan_validator(on, std::move(proving)), on.name);
    }
    options.bands = !args.no_bands;
    options.fine_graining = !args.no_fine_graining;
    options.filled = !args.no_filled;
    options.learn = !args.no_learning;
    options.objective = objective(args.objective);
    options.max_rejected = args.max_rejected;
    return options;
  };
  planner::PlanningOptions options = options_for(machine);
  ProgressBar bar("planning");
  std::string current;
  options.progress = [&](const std::string& phase, double f) {
    // One bar across the phases, weighted by their usual share of the time.
    static const std::pair<const char*, std::pair<double, double>> weights[] = {
        {"voxelize", {0.0, 0.1}}, {"primitives", {0.1, 0.7}}, {"atoms", {0.7, 0.85}}, {"search", {0.85, 1.0}}};
    for (const auto& [name, span] : weights)
      if (phase == name) bar.update(span.first + f * (span.second - span.first));
  };
  const planner::PlanningResult result = planner::plan_part(mesh, args.part, machine, options);
  bar.finish();
  const planner::ReportSources sources{args.part, args.machine, machine.name, machine_text};
  std::fputs(planner::plan_summary(result, sources, args.verbose).c_str(), stdout);
  if (args.compare) {
    ProgressBar others("comparing");
    int planned = 0;
    const planner::WaysCompared compared =
        planner::compare_ways(machine, result, [&](const config::Machine& on) {
          const planner::PlanningResult r = planner::plan_part(mesh, args.part, on, options_for(on));
          others.update(++planned / 2.0);
          return r;
        });
    others.finish();
    std::fputs(planner::ways_compared_text(compared).c_str(), stdout);
  }
  const std::string plan_dir = !args.output.empty() ? args.output : args.export_dir.empty() ? "" : args.export_dir + "/plan";
  if (!plan_dir.empty()) {
    if (args.output.empty()) std::filesystem::create_directories(args.export_dir);
    planner::write_plan_directory(result, sources, plan_dir);
    std::printf("wrote       %s/plan.json, design.vdb, %zu primitive and %zu plan .vdb files\n", plan_dir.c_str(),
                result.primitives.size(), result.plans.size());
  }
  std::printf("time       ");
  double total = 0;
  for (const auto& [phase, seconds] : result.timings) {
    std::printf(" %s %.2f s,", phase.c_str(), seconds);
    total += seconds;
  }
  std::printf(" total %.2f s\n", total);
  const bool exports = !args.export_dir.empty() && result.verdict.manufacturable() && !result.plans.empty();
  // The plan in memory is the plan on disk (PlanInMemory tests): report and export need not
  // read its solids back.
  const plan::PlanFile in_memory =
      args.report || exports ? planner::to_plan_file(result, sources, plan_dir) : plan::PlanFile{};
  if (args.report) {  // also, and most of all, for a part that is not manufacturable
    report::ReportRequest request;
    request.plan = plan_dir;
    request.in_memory = &in_memory;
    write_job_report(request);
  }
  if (exports) {
    ExportRequest request;
    request.plan = plan_dir;
    request.output = args.export_dir;
    request.dialect = args.dialect;
    const int code = export_plan_programs(in_memory, request);
    if (code != kSuccess) return code;
  }
  return result.verdict.manufacturable() && !result.plans.empty() ? int(kSuccess) : int(kNotManufacturable);
}

}  // namespace

void add_plan_command(CLI::App& app, Runner& runner) {
  auto args = std::make_shared<PlanArgs>();
  auto* cmd = app.add_subcommand("plan",
                                 "Find cost-optimal hybrid plans for a part on a machine: primitives, atoms, "
                                 "manufacturability verdict and the k best plans, each proven by execution on the simulated machine "
                                 "(candidates that fail are rejected with their reasons; exit 4 when none is left)");
  cmd->add_option("PART", args->part, "Part mesh (closed STL, mm)")->required();
  cmd->add_option("-m,--machine", args->machine, "Machine description (YAML)")->required();
  cmd->add_option("-o,--output", args->output,
                  "Write plan.json and .vdb files of the design, primitives and plans into this directory");
  cmd->add_option("--export", args->export_dir,
                  "Also write the best plan's G-code into this directory (as `hybridctl export`; the plan goes to "
                  "-o, or to DIR/plan)");
  cmd->add_flag("--report", args->report,
                "Also write the job report, DIR/report.html and its PNG snapshots (as `hybridctl report DIR`)");
  cmd->add_flag("--compare", args->compare,
                "Also plan the part milled from stock only (the machine without its heads) and deposited only "
                "(without its tools), and print each way's best plan with its machine time and money beside the "
                "hybrid one (docs/costs.md)");
  cmd->add_flag("--verbose", args->verbose,
                "A refusal's proof in atoms and regions too, where its places are said in shop words (always in "
                "plan.json)");
  cmd->add_option("--dialect", args->dialect, "With --export: rs274ngc or fanuc (default: the machine file's)");
  cmd->add_option("--voxel", args->voxel, "Voxel size in mm (default: the machine file's planning.voxel_size)")
      ->check(greater_than(0));
  add_memory_budget_option(cmd, args->memory_budget);
  cmd->add_option("--tolerance", args->tolerance, "Tolerance in mm on the STL's real surface, both ways: every plan offered makes a part within it by exact verification (default: the machine file's planning.tolerance)")
      ->check(at_least(0));
  cmd->add_option("--top", args->top, "How many plans (default: the machine file's planning.top_k)")
      ->check(greater_than(0));
  cmd->add_option("--reuse", args->reuse, "How often one primitive may appear in a plan")
      ->default_val(1)
      ->check(between(1, 8));
  cmd->add_option("--search-time", args->search_time,
                  "Seconds the plan search may take (default: no budget, only its expansion and state limits). "
                  "Plans the exact search has not proven by half of it are built step by step or come from weighted A*, "
                  "each with its proven gap; a budget makes the result depend on the machine's speed")
      ->check(greater_than(0));
  cmd->add_option("--primitive", args->primitive_files,
                  "Extra primitive FILE:am or FILE:sm (STL, or .vdb on the plan's voxel grid); repeatable");
  cmd->add_option("--stock", args->stock_files,
                  "Raw stock as a file (STL, or .vdb on the plan's voxel grid) in the part's frame: a casting, a blank, "
                  "a worn part to repair; replaces the machine file's raw stocks; repeatable");
  cmd->add_flag("--no-validate", args->no_validate,
                "Offer the plans the search finds without executing them first (for comparison and benchmarks; "
                "export and run still refuse a plan that does not make the part)");
  cmd->add_flag("--no-bands", args->no_bands,
                "Search without banded primitives (\"mill up to here, deposit from here on\", docs/bands.md): only "
                "whole-part ones, for comparison and benchmarks");
  cmd->add_flag("--no-fine-graining", args->no_fine_graining,
                "Do not split atoms that straddle the design with primitives restricted to their neighbourhood "
                "(iterative fine-graining, docs/bands.md): for comparison and benchmarks");
  cmd->add_flag("--no-filled", args->no_filled,
                "Do not offer filled deposits (a head's overfill with holes and overhangs filled solid, to be milled "
                "back, docs/support.md): for comparison and benchmarks");
  cmd->add_flag("--no-learning", args->no_learning,
                "Do not correct the search from what rejected candidates' execution showed the primitives do not do "
                "(docs/validation.md): for comparison and benchmarks");
  add_objective_option(cmd, args->objective);
  cmd->add_option("--max-rejected", args->max_rejected,
                  "How many candidate plans validation may turn down before the search gives up")
      ->capture_default_str()
      ->check(between(1, 1000));
  cmd->callback([&runner, args] { runner = [args] { return run_plan(*args); }; });
}

}  // namespace hybridctl::cli
