#include <cstdio>
#include <memory>

#include "cli/commands.hpp"
#include "config/machine_loader.hpp"
#include "gcode/check.hpp"
#include "gcode/files.hpp"

namespace hybridctl::cli {

void add_gcode_command(CLI::App& app, Runner& runner) {
  auto* gcode = app.add_subcommand("gcode", "Work with G-code programs");
  gcode->require_subcommand(1);
  auto* check = gcode->add_subcommand(
      "check",
      "Interpret a G-code program for a machine and report: G-code errors (file:line:column), moves outside the "
      "envelope (end points and arc extremes, machine coordinates via the setups' work_origin), tool numbers the "
      "machine lacks, deposition codes without a head selected, the spindle started with a head active, cuts with "
      "the spindle stopped, and the cycle time with what it includes (motion: trapezoidal feed and acceleration "
      "limits per axis, every move from rest to rest; dwells; tool changes, head switches, setup changes and "
      "refixtures at the machine file's costs times), the one time model every command prints. Exit 0 when clean, 3 on bad input or any problem. See docs/gcode.md.");
  auto file = std::make_shared<std::string>();
  auto machine_file = std::make_shared<std::string>();
  check->add_option("FILE", *file, "G-code program (RS274NGC/LinuxCNC or Fanuc-style)")->required();
  check->add_option("--machine,-m", *machine_file, "Machine description (YAML), see docs/machine-file.md")->required();
  check->callback([&runner, file, machine_file] {
    runner = [file, machine_file] {
      const config::Machine machine = config::load_machine(*machine_file);
      const std::string text = gcode::read_text_file(*file);
      const gcode::CheckReport report = gcode::check_program(text, machine, *file);
      std::fputs(report.str().c_str(), stdout);
      std::fflush(stdout);
      return report.clean() ? int(kSuccess) : int(kBadInput);
    };
  });
}

}  // namespace hybridctl::cli
