#pragma once
// A program as the post-processor writes it, with its structure kept: the lines, for each
// line the action and the toolpath move it came from, and the table of the program's
// actions (number, primitive, mode, process, instrument, setup, first and last line).
// `hybridctl run` reports per action from the table, never by searching the text.
//
// The `(action K: primitive P, ...)` comment that opens each action's block is for people
// reading the G-code. The one place allowed to read it back is PostedProgram::from_lines
// (and from_text): a program given as a file, with no plan behind it, has only what its
// text says. No other code parses those comments.
//
// (gcode::Program in gcode/interpreter.hpp is something else: what a program *does*, its
// motions and events, as the interpreter executes it.)

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "gcode/toolpath.hpp"

namespace hybridctl::gcode {

enum class ActionMode { Additive, Subtractive };

/// One action's block in a program.
struct ProgramAction {
  int number = 0;                ///< the plan's action number (ActionProgram::action), as in its heading
  std::string primitive;         ///< e.g. "P4"
  ActionMode mode = ActionMode::Additive;
  Process process = Process::Deposition;
  std::string instrument;        ///< as the heading names it: "head ded", "T1 10 mm flat rougher"
  std::string setup;             ///< setup name
  std::uint32_t first_line = 0;  ///< 1-based: the heading comment
  std::uint32_t last_line = 0;   ///< 1-based, inclusive: its last line before the next action or the program end

  /// "action 4: primitive P7, subtractive milling with T1 10 mm flat rougher in setup top":
  /// the heading comment's text, the action's name in reports.
  std::string heading() const;

  friend bool operator==(const ProgramAction&, const ProgramAction&) = default;
};

/// Where a line came from.
struct LineOrigin {
  std::optional<std::size_t> action;  ///< index into PostedProgram::actions; none: program header or end
  std::optional<std::size_t> move;    ///< index into that action's toolpath moves; none: a generated line

  friend bool operator==(const LineOrigin&, const LineOrigin&) = default;
};

struct PostedProgram {
  std::vector<std::string> lines;     ///< the program's lines, without their '\n'
  std::vector<LineOrigin> origins;    ///< one per line
  std::vector<ProgramAction> actions; ///< in program order

  /// The program text: every line followed by '\n' (what the post-processor writes).
  std::string text() const;

  /// The action that 1-based `line` belongs to, or null (header, program end, out of range).
  const ProgramAction* action_at(std::uint32_t line) const;

  /// Recovers the structure of a program from its lines: an action starts at each line that
  /// is (after an optional block number `N..`) exactly our heading comment
  /// `(action K: primitive P, additive|subtractive deposition|milling with I in setup S)`;
  /// the lines before the first are the header. The text does not say where the program's
  /// end block begins, so the last action runs to the last line; no line has a move.
  /// A program without such comments has no actions.
  static PostedProgram from_lines(std::vector<std::string> lines);

  /// from_lines on `text` split into lines as the interpreter splits it (gcode::for_each_line).
  static PostedProgram from_text(std::string_view text);
};

/// Text that a comment can hold, in plain ASCII in every dialect (the one place comment
/// text is made): '(' and ')' become '[' and ']', line breaks and tabs spaces, other
/// control bytes '?'. A UTF-8 character outside ASCII is spelled out where there is a
/// readable spelling ("∪" "+", "−" "-", "³" "3", "²" "2", "°" " deg", "ø" "dia ", "×" "x",
/// dashes "-", "µ" "u", "±" "+/-", "≤" "<=", "≥" ">=", "→" "->") and is one '?' otherwise,
/// as is each broken UTF-8 sequence. So the plan "((P1 ∪ P9) − P7)" reads
/// "[[P1 + P9] - P7]" in a comment.
std::string comment_text(std::string_view text);

}  // namespace hybridctl::gcode
