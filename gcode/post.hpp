#pragma once
// The post-processor: plan actions' toolpaths (gcode/toolpath.hpp) into a program in a
// machine's dialect: its text, and which action and move made each line
// (gcode/program.hpp). docs/gcode.md lists what each dialect gets.
//
//   Rs274ngc (LinuxCNC, the default): header `G21 G90 G17 G94 G40 G49 G80` and the first
//     setup's work offset; `T.. M6` then `G43 H..`; deposition codes must be M62..M65 P..
//     (and the power template M67/M68 E.. Q{power}), program end M2 by default.
//   Fanuc-style ISO: `%`, `O1000 (NAME)`, N numbers in steps of 10, whole numbers written
//     with a decimal point (`X10.`: no trailing-point ambiguity), M30, `%`.
//
// Per action: a comment block (action, primitive, mode, volume, estimated time), a tool
// or head change when the instrument differs from the previous action's (retract with
// G53 G0 to the top of Z travel, spindle and coolant off, `T.. M6`), a setup change when
// the setup differs (retract, rotary move `G0 B.. C..` when the setup has rotary
// positions and the machine those axes, otherwise, or when the setup needs manual
// refixturing, a program stop with an operator message; then the work offset), spindle
// `S.. M3` for milling, coolant when asked, the head's power template once, an approach
// to the path's start, the moves with deposition on/off codes where PathMove::process_on
// changes, deposition off and a retract to the path's safe Z. At the end: spindle,
// coolant and deposition off, retract, program end.
//
// Numbers have at most 4 decimals, trailing zeros trimmed, never "-0"; F is written only
// when it changes. Output is deterministic (no dates).
//
// Before returning any text the program is interpreted with gcode::Interpreter and every
// motion checked against the machine's envelope (machine coordinates = work coordinates
// + the setup's work_origin). Any problem throws InputError naming the action, the move
// and the generated line, and nothing is returned or written.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "config/machine.hpp"
#include "gcode/program.hpp"
#include "gcode/toolpath.hpp"

namespace hybridctl::gcode {

struct PostOptions {
  std::optional<config::Dialect> dialect;  ///< default: the machine's gcode.dialect
  std::string program_name = "hybridctl";  ///< written in the header comment
  bool coolant = false;                    ///< coolant on (M8) while milling
};

/// One program running every action in order, with its structure (gcode/program.hpp): for
/// each line the action (index into `actions`) and the move it came from, and the table of
/// actions. Throws InputError when an action cannot be written for the machine or leaves
/// its envelope.
PostedProgram post_program(const std::vector<ActionProgram>& actions, const config::Machine& machine,
                           const PostOptions& options = {});

/// A standalone program for one action (header, its tool and setup, moves, end). Same
/// errors as post_program.
PostedProgram post_action(const ActionProgram& action, const config::Machine& machine, const PostOptions& options = {});

/// post_program(...).text().
std::string write_program(const std::vector<ActionProgram>& actions, const config::Machine& machine,
                          const PostOptions& options = {});

/// post_action(...).text().
std::string write_action(const ActionProgram& action, const config::Machine& machine, const PostOptions& options = {});

/// ".ngc" for rs274ngc, ".nc" for fanuc.
std::string program_extension(config::Dialect dialect);

/// A code the machine file gives that `dialect`'s controller does not run (the RS274NGC
/// dialect writes only codes LinuxCNC runs): the key in the machine file
/// ("gcode.m_codes.spindle_cw", "heads[0].codes.on") and what is wrong and expected.
struct PostingProblem {
  std::string key;
  std::string message;
};
std::optional<PostingProblem> posting_problem(const config::Machine& machine, config::Dialect dialect);

/// config::parse_machine, then posting_problem for the machine's own dialect: a machine
/// file whose programs could never be posted is refused when it is loaded, with the
/// place of the key (MachineFileError, exit 3), not after planning.
config::Machine parse_postable_machine(std::string_view yaml_text, const std::string& file_name);
config::Machine load_postable_machine(const std::filesystem::path& path);

struct ProgramFiles {
  std::filesystem::path program;               ///< DIR/NAME.ext: every action
  std::vector<std::filesystem::path> actions;  ///< DIR/NAME-action-NN.ext, one per action
};

/// Generates and checks every text first, then writes them atomically; on any error no
/// file is written. `directory` must exist.
ProgramFiles write_program_files(const std::filesystem::path& directory, const std::string& name,
                                 const std::vector<ActionProgram>& actions, const config::Machine& machine,
                                 const PostOptions& options = {});

/// A number as the post-processor writes it: at most 4 decimals, trailing zeros trimmed,
/// no "-0"; with `decimal_point` a whole number keeps its point ("10.", Fanuc).
std::string format_number(double value, bool decimal_point = false);

/// Appends format_number(value, decimal_point) to `out` without allocating.
void append_number(std::string& out, double value, bool decimal_point = false);

}  // namespace hybridctl::gcode
