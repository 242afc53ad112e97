// hybridctl report: the job report of a plan directory as one self-contained HTML page
// with PNG snapshots beside it (docs/report.md).

#include <chrono>
#include <cstdio>
#include <memory>

#include "cli/commands.hpp"
#include "cli/report_job.hpp"

namespace hybridctl::cli {

void write_job_report(const report::ReportRequest& request) {
  const auto start = std::chrono::steady_clock::now();
  const report::ReportResult r = report::write_report(request);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("report      %s: %.1f MB, %zu triangles, %zu toolpath segments, %d plans with %d actions (%.2f s)\n",
              r.page.c_str(), double(r.bytes) / 1e6, r.triangles, r.segments, r.plans, r.actions, seconds);
  if (!r.snapshots.empty()) {
    std::printf("snapshots  ");
    for (const auto& s : r.snapshots) std::printf(" %s", s.c_str());
    std::printf("\n");
  }
}

namespace {

struct ReportArgs {
  std::string plan, output, as_built, run_report;
  bool no_snapshots = false;
  std::size_t exact_plans = report::ReportRequest{}.exact_plans;
};

}  // namespace

void add_report_command(CLI::App& app, Runner& runner) {
  auto a = std::make_shared<ReportArgs>();
  auto* cmd = app.add_subcommand(
      "report",
      "Write the job report of a plan directory: one self-contained HTML page (3D view of the design, primitives, "
      "atoms and offending atoms, each plan's exact deviation painted on the design's STL, the plans as strips of "
      "states, each action's toolpath with a layer slider, after a dry run what it built and its alarms) and PNG "
      "snapshots beside it (docs/report.md)");
  cmd->add_option("PLAN", a->plan, "plan.json or its directory (hybridctl plan -o DIR)")->required();
  cmd->add_option("-o,--output", a->output, "The page (default: PLAN_DIR/report.html); the PNGs go beside it");
  cmd->add_option("--as-built", a->as_built, "What a run of plan 1 built (sim serve --as-built; dry-run's as-built.vdb)");
  cmd->add_option("--run-report", a->run_report, "That run's report (sim serve --report; dry-run's sim-report.json): alarms at their place");
  cmd->add_flag("--no-snapshots", a->no_snapshots, "Do not write the PNG snapshots");
  cmd->add_option("--exact-plans", a->exact_plans,
                  "How many plans, the best first, to replay and paint with their exact deviation on the design's "
                  "STL (0: none; each costs about what validating it did)")
      ->capture_default_str();
  cmd->callback([&runner, a] {
    runner = [a] {
      report::ReportRequest request;
      request.plan = a->plan;
      request.output = a->output;
      request.as_built = a->as_built;
      request.run_report = a->run_report;
      request.snapshots = !a->no_snapshots;
      request.exact_plans = a->exact_plans;
      write_job_report(request);
      return int(kSuccess);
    };
  });
}

}  // namespace hybridctl::cli
