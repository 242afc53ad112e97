#pragma once
// The machine a plan is exported or run with: the one embedded in its plan.json, or a
// machine file given with --machine when it is the same machine (the same text, by hash)
// or the override is asked for. Plans older than the embedding name only a file, found
// relative to plan.json's directory, then to the working directory.

#include <string>
#include <string_view>

#include "config/machine.hpp"
#include "plan/plan_file.hpp"

namespace hybridctl::plan {

// FNV-1a 64 of a machine file's text, as 16 lower-case hex digits (plan.json's machine.hash).
std::string machine_text_hash(std::string_view yaml_text);

struct MachineChoice {
  std::string file;       // --machine; empty: the plan's own
  bool override = false;  // --machine-override: take `file` even when it is another machine
};

struct PlanMachine {
  config::Machine machine;
  std::string file;  // the machine file it came from; empty when embedded
  std::string text;  // its YAML
  std::string note;  // one line for people (stderr) when --machine was given for a plan that embeds one
};

// Throws hybridctl::InputError when --machine is another machine without the override, or
// an older plan's machine file is found nowhere (saying where it was looked for), and
// config::MachineFileError for a machine text with problems.
PlanMachine plan_machine(const PlanFile& file, const MachineChoice& choice);

}  // namespace hybridctl::plan
