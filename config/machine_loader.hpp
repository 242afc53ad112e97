#pragma once
// Loading a machine file (YAML) into config::Machine, reporting every problem in one pass
// as "file:line:column: what is wrong, what was expected". docs/machine-file.md is the
// reference for the file format.

#include <filesystem>
#include <string>
#include <string_view>

#include "config/diagnostic.hpp"
#include "config/machine.hpp"
#include "config/summary.hpp"

namespace hybridctl::config {

/// Reads and parses `path`. An unreadable file is one diagnostic "path: cannot read: <reason>".
/// Throws MachineFileError (and nothing else) on any problem.
Machine load_machine(const std::filesystem::path& path);

/// The text of the machine file at `path`, as load_machine reads it (what plan.json embeds).
/// Throws MachineFileError "path: cannot read: <reason>".
std::string read_machine_text(const std::filesystem::path& path);

/// Parses `yaml_text`; `file_name` is used in diagnostics only (for a machine embedded in
/// a plan: "DIR/plan.json (embedded machine)").
/// Throws MachineFileError (and nothing else) on any problem.
Machine parse_machine(std::string_view yaml_text, std::string file_name);

/// A diagnostic about the value at `key_path` ("gcode.m_codes.spindle_cw",
/// "heads[0].codes.on") of a machine file that parses: at the value's line and column, or
/// at the deepest key of the path the file writes when it leaves the rest to defaults.
Diagnostic diagnostic_at(std::string_view yaml_text, const std::string& file_name, std::string_view key_path, std::string message);

}  // namespace hybridctl::config
