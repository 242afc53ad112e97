#include <cstdio>
#include <memory>

#include "cli/commands.hpp"
#include "config/machine_loader.hpp"
#include "gcode/post.hpp"

namespace hybridctl::cli {

void add_machine_command(CLI::App& app, Runner& runner) {
  auto* machine = app.add_subcommand("machine", "Work with machine description files (YAML)");
  machine->require_subcommand(1);
  auto* check = machine->add_subcommand(
      "check", "Validate a machine file and print a summary; every problem is reported as file:line:column");
  auto file = std::make_shared<std::string>();
  check->add_option("FILE", *file, "Machine description (YAML), see docs/machine-file.md")->required();
  check->callback([&runner, file] {
    runner = [file] {
      try {
        const config::Machine m = gcode::load_postable_machine(*file);
        std::printf("%s: ok\n%s", file->c_str(), config::summarize(m).c_str());
        return int(kSuccess);
      } catch (const config::MachineFileError& e) {
        for (const auto& d : e.diagnostics()) std::fprintf(stderr, "%s\n", d.str().c_str());
        std::fprintf(stderr, "%s: %zu problem%s\n", file->c_str(), e.diagnostics().size(),
                     e.diagnostics().size() == 1 ? "" : "s");
        return int(kBadInput);
      }
    };
  });
}

}  // namespace hybridctl::cli
