#pragma once
// The hybridctl subcommands. Each registers itself on the CLI11 app and runs when
// chosen; a run returns the process exit code.

#include <CLI/CLI.hpp>

#include <functional>

namespace hybridctl::cli {

// Exit codes, documented in `hybridctl --help` and the README.
enum ExitCode : int {
  kSuccess = 0,
  kInternalError = 1,
  kUsage = 2,
  kBadInput = 3,
  kNotManufacturable = 4,
  kMachineStopped = 5,  // run: the machine stopped (alarm, abort, operator) before the program's end
  kUnreachable = 6,     // run, status: the controller could not be reached; cell: the database
};

using Runner = std::function<int()>;

// Each adds its subcommand to `app` and returns what runs it.
void add_machine_command(CLI::App& app, Runner& runner);
void add_voxelize_command(CLI::App& app, Runner& runner);
void add_inspect_command(CLI::App& app, Runner& runner);
void add_plan_command(CLI::App& app, Runner& runner);
void add_gcode_command(CLI::App& app, Runner& runner);
void add_export_command(CLI::App& app, Runner& runner);
void add_sim_command(CLI::App& app, Runner& runner);
void add_status_command(CLI::App& app, Runner& runner);
void add_run_command(CLI::App& app, Runner& runner);
void add_dry_run_command(CLI::App& app, Runner& runner);
void add_bridge_command(CLI::App& app, Runner& runner);
void add_report_command(CLI::App& app, Runner& runner);
void add_cell_command(CLI::App& app, Runner& runner);

}  // namespace hybridctl::cli
