// hybridctl: plans and runs hybrid (additive + subtractive) manufacturing.

#include <cstdio>
#include <exception>

#include "cli/commands.hpp"
#include "cli/ranges.hpp"
#include "common/error.hpp"
#include "drivers/transport.hpp"
#include "validation/execution.hpp"

int main(int argc, char** argv) {
  using namespace hybridctl::cli;
  CLI::App app{
      "hybridctl plans hybrid manufacturing (metal deposition and milling on one machine)\n"
      "from a part (STL) and a machine description (YAML).\n\n"
      "Exit codes: 0 success, 1 internal error, 2 usage error, 3 bad input (file, YAML, STL, G-code),\n"
      "4 part not manufacturable with the machine's primitives (plan), 5 the machine stopped before\n"
      "the program's end (run), 6 the controller could not be reached (run, status), or the cell's database (cell).",
      "hybridctl"};
  app.set_version_flag("--version", "hybridctl 0.1.0");
  app.require_subcommand(1);
  app.failure_message(failure_message);
  Runner runner;
  add_machine_command(app, runner);
  add_voxelize_command(app, runner);
  add_inspect_command(app, runner);
  add_plan_command(app, runner);
  add_gcode_command(app, runner);
  add_export_command(app, runner);
  add_sim_command(app, runner);
  add_status_command(app, runner);
  add_run_command(app, runner);
  add_dry_run_command(app, runner);
  add_bridge_command(app, runner);
  add_report_command(app, runner);
  add_cell_command(app, runner);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? kSuccess : kUsage;
  }
  try {
    return runner ? runner() : kUsage;
  } catch (const hybridctl::validation::NotManufacturableError& e) {
    std::fflush(stdout);
    std::fprintf(stderr, "hybridctl: not manufacturable: %s\n", e.what());
    return kNotManufacturable;
  } catch (const hybridctl::InputError& e) {
    std::fflush(stdout);  // what was printed so far comes before the error
    std::fprintf(stderr, "hybridctl: error: %s\n", e.what());
    return kBadInput;
  } catch (const hybridctl::drivers::TransportError& e) {
    std::fflush(stdout);
    std::fprintf(stderr, "hybridctl: cannot reach the controller: %s\n", e.what());
    return kUnreachable;
  } catch (const std::exception& e) {
    std::fflush(stdout);
    std::fprintf(stderr, "hybridctl: internal error: %s\n", e.what());
    return kInternalError;
  }
}
