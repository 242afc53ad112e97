#include "plan/plan_machine.hpp"

#include <filesystem>

#include "common/error.hpp"
#include "config/machine_loader.hpp"
#include "common/hash.hpp"

namespace hybridctl::plan {
namespace {

namespace fs = std::filesystem;

std::string hex16(std::uint64_t v) {
  static const char digits[] = "0123456789abcdef";
  std::string out(16, '0');
  for (int i = 15; i >= 0; --i, v >>= 4) out[std::size_t(i)] = digits[v & 0xF];
  return out;
}

// --machine for a plan that embeds its machine.
PlanMachine given_machine(const PlanFile& file, const MachineChoice& choice) {
  PlanMachine m;
  m.file = choice.file;
  m.text = config::read_machine_text(choice.file);
  const std::string hash = machine_text_hash(m.text);
  if (file.machine_yaml.empty()) {
    // An older plan: nothing to compare with; --machine is taken as before.
  } else if (hash == file.machine_hash) {
    m.note = "--machine " + choice.file + ": the same machine as the plan's embedded '" + file.machine_name +
             "' (hash " + hash + ")";
  } else if (choice.override) {
    m.note = "--machine " + choice.file + " (hash " + hash + ") overrides the plan's embedded machine '" +
             file.machine_name + "' (hash " + file.machine_hash + ") as --machine-override asks";
  } else {
    throw InputError("--machine " + choice.file + ": not the machine the plan was made with (hash " + hash +
                     "; the plan embeds '" + file.machine_name + "', hash " + file.machine_hash +
                     "); leave --machine out to use the embedded one, or give --machine-override");
  }
  m.machine = config::parse_machine(m.text, choice.file);
  return m;
}

// An older plan's machine file: relative to plan.json's directory, then to the working directory.
PlanMachine named_machine(const PlanFile& file) {
  const fs::path named = file.machine_file;
  fs::path found;
  if (named.is_absolute()) {
    found = named;
  } else if (fs::exists(file.directory / named)) {
    found = file.directory / named;
  } else if (fs::exists(named)) {
    found = named;
  } else {
    throw InputError((file.directory / "plan.json").string() + ": the machine file '" + file.machine_file +
                     "' it names is neither in the plan's directory (" + (file.directory / named).string() +
                     ") nor in the working directory (" + fs::absolute(named).string() +
                     "); expected --machine FILE (the plan embeds no machine: it is from an older hybridctl)");
  }
  PlanMachine m;
  m.file = found.string();
  m.text = config::read_machine_text(found);
  m.machine = config::parse_machine(m.text, m.file);
  return m;
}

}  // namespace

std::string machine_text_hash(std::string_view yaml_text) { return hex16(fnv1a64(yaml_text)); }

PlanMachine plan_machine(const PlanFile& file, const MachineChoice& choice) {
  if (!choice.file.empty()) return given_machine(file, choice);
  if (file.machine_yaml.empty()) return named_machine(file);
  PlanMachine m;
  m.text = file.machine_yaml;
  m.machine = config::parse_machine(m.text, (file.directory / "plan.json").string() + " (embedded machine)");
  return m;
}

}  // namespace hybridctl::plan
