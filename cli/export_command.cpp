// hybridctl export: a plan's actions as G-code programs for the machine.

#include <cstdio>
#include <filesystem>
#include <memory>

#include "cli/commands.hpp"
#include "cli/ranges.hpp"
#include "cli/export_run.hpp"
#include "cli/progress.hpp"
#include "common/error.hpp"
#include "plan/plan_machine.hpp"
#include "gcode/check.hpp"
#include "gcode/files.hpp"
#include "toolpaths/plan_export.hpp"
#include "gcode/tool_table.hpp"
#include "validation/execution.hpp"

namespace hybridctl::cli {

namespace fs = std::filesystem;

int export_plan_programs(const ExportRequest& request) {
  return export_plan_programs(plan::read_plan_file(request.plan), request);
}

int export_plan_programs(const plan::PlanFile& file, const ExportRequest& request) {
  const plan::PlanMachine chosen = plan::plan_machine(file, {request.machine, request.machine_override});
  if (!chosen.note.empty()) std::fprintf(stderr, "%s\n", chosen.note.c_str());
  const config::Machine& machine = chosen.machine;
  if (file.plans.empty()) throw InputError(request.plan + ": the plan file holds no plans (the part was not manufacturable)");
  if (request.rank < 1 || request.rank > int(file.plans.size()))
    throw InputError("--plan " + std::to_string(request.rank) + ": expected 1.." + std::to_string(file.plans.size()) +
                     " (the plans in " + request.plan + ")");
  const plan::PlanFilePlan& plan = file.plans[std::size_t(request.rank - 1)];

  toolpaths::ExportOptions options;
  if (!request.dialect.empty()) {
    if (request.dialect == "rs274ngc" || request.dialect == "linuxcnc") {
      options.post.dialect = config::Dialect::Rs274ngc;
    } else if (request.dialect == "fanuc") {
      options.post.dialect = config::Dialect::Fanuc;
    } else {
      throw InputError("--dialect " + request.dialect + ": expected rs274ngc or fanuc");
    }
  }
  if (request.arcs == "lines") options.arcs.output = toolpaths::ArcOutput::Lines;
  const std::string name = "plan-" + std::to_string(request.rank);
  options.post.program_name = name + " " + plan.expression;
  ProgressBar bar("toolpaths");
  options.progress = [&](int action, int actions) { bar.update(double(action - 1) / double(actions)); };
  // Each action's toolpath is planned against the material the ones before it really
  // leave, and the program is executed from the raw stock before anything is written.
  validation::ExecutionOptions execution;
  execution.export_options = options;
  const validation::Execution run = validation::require_proven(
      file, plan, machine, execution, "plan " + std::to_string(request.rank) + " (" + plan.expression + ")");
  const toolpaths::PlanExport& exported = run.exported;
  bar.finish();

  const std::vector<gcode::ActionProgram> programs = exported.programs();
  if (programs.empty()) throw InputError("plan " + std::to_string(request.rank) + " (" + plan.expression + ") has no action that makes G-code");
  fs::create_directories(request.output);
  const gcode::ProgramFiles written = gcode::write_program_files(request.output, name, programs, machine, options.post);
  gcode::write_text_file(fs::path(request.output) / "tool.tbl", gcode::linuxcnc_tool_table(machine));

  std::printf("plan        %d: %s  cost %.4f\n", request.rank, plan.expression.c_str(), plan.cost);
  std::size_t next = 0;
  for (const toolpaths::ExportedAction& a : exported.actions) {
    if (!a.makes_gcode) {
      std::printf("  %d) %-4s %s\n", a.step, a.primitive.c_str(), a.note.c_str());
      continue;
    }
    const fs::path& path = written.actions[next++];
    const gcode::CheckReport report =
        gcode::check_program(gcode::read_text_file(path), machine, path.string());
    std::printf("  %d) %-4s %-44s %9.1f mm³  %6zu moves  motion %s  -> %s\n", a.step, a.primitive.c_str(),
                a.program.label.c_str(), a.program.volume, a.program.path.moves.size(),
                gcode::format_duration(report.time.motion + report.time.dwell).c_str(),
                path.filename().string().c_str());
    for (const std::string& w : a.program.path.warnings) std::printf("       warning: %s\n", w.c_str());
  }
  const gcode::CheckReport whole = gcode::check_program(run.program.text(), machine, written.program.string());
  std::printf("cycle time  %s: %s\n", written.program.filename().string().c_str(), whole.time.str().c_str());
  const plan::Deviation& d = run.deviation;
  std::printf("executed    from the raw stock: %zu lines; as built on the voxels %s\n", run.program.lines.size(),
              plan::deviation_text(d, file.band()).c_str());
  if (run.exact) std::printf("exact       %s\n", plan::exact_deviation_text(*run.exact).c_str());
  std::printf("wrote       %s, %zu action programs and tool.tbl in %s\n", written.program.filename().string().c_str(),
              written.actions.size(), request.output.c_str());
  return kSuccess;
}

void add_export_command(CLI::App& app, Runner& runner) {
  auto request = std::make_shared<ExportRequest>();
  auto* cmd = app.add_subcommand("export",
                                 "Turn a plan's actions into G-code: deposition (contour then rasters) and pocket milling per action, "
                                 "one program per action plus one for the whole plan, and a LinuxCNC tool table; "
                                 "each action planned against the material the ones before it leave, the program "
                                 "executed on the simulated machine from the raw stock first (exit 4 and nothing "
                                 "written on a skipped layer, an unreachable region, a rapid or body into material, a "
                                 "gouge, a refused line, a bead over air or a part out of tolerance)");
  cmd->add_option("PLAN", request->plan, "plan.json (or its directory) written by `hybridctl plan -o`")->required();
  cmd->add_option("-o,--output", request->output, "Directory for the programs (created if missing)")->required();
  cmd->add_option("--plan", request->rank, "Which plan, by rank (1 = cheapest)")->default_val(1)->check(greater_than(0));
  cmd->add_option("--dialect", request->dialect, "rs274ngc (LinuxCNC) or fanuc (default: the machine file's gcode.dialect)");
  cmd->add_option("-m,--machine", request->machine,
                  "Machine description (default: the one plan.json embeds); refused when it is another machine than "
                  "the plan's, unless --machine-override");
  cmd->add_flag("--machine-override", request->machine_override,
                "With --machine: use it even when it is not the machine the plan was made with");
  cmd->add_option("--arcs", request->arcs,
                  "fit: feed moves that follow a circle within 0.001 mm become G2/G3 arcs; lines: G1 moves only, as "
                  "the toolpaths make them")
      ->default_val("fit")
      ->check(CLI::IsMember({"fit", "lines"}));
  cmd->callback([&runner, request] { runner = [request] { return export_plan_programs(*request); }; });
}

}  // namespace hybridctl::cli
