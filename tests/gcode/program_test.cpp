// The program model the post-processor returns (gcode/program.hpp): every line knows its
// action and move, the action table agrees with the text it describes, and
// PostedProgram::from_text reads the same table back from the text alone.

#include "gcode/program.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "config/machine_loader.hpp"
#include "gcode/post.hpp"
#include "sample_programs.hpp"

namespace {

using namespace hybridctl::gcode;
using hybridctl::config::Machine;
using hybridctl::gcode::samples::sample_actions;

Machine example(const std::string& name) {
  return hybridctl::config::load_machine(std::string(HYBRIDCTL_SOURCE_DIR) + "/examples/machines/" + name);
}

std::string g_code(MoveKind k) {
  switch (k) {
    case MoveKind::Rapid: return "G0";
    case MoveKind::Feed: return "G1";
    case MoveKind::ArcCw: return "G2";
    case MoveKind::ArcCcw: return "G3";
  }
  return "";
}

/// The line without its block number ("N120 G1 X1" -> "G1 X1").
std::string without_block_number(const std::string& line) {
  if (line.empty() || line[0] != 'N') return line;
  const auto space = line.find(' ');
  return space == std::string::npos ? line : line.substr(space + 1);
}

void expect_table_agrees_with_actions(const PostedProgram& p, const std::vector<ActionProgram>& actions,
                                      const Machine& m) {
  ASSERT_EQ(p.lines.size(), p.origins.size());
  ASSERT_EQ(p.actions.size(), actions.size());
  for (std::size_t i = 0; i < actions.size(); ++i) {
    const ProgramAction& row = p.actions[i];
    const ActionProgram& a = actions[i];
    EXPECT_EQ(row.number, a.action);
    EXPECT_EQ(row.primitive, a.primitive);
    EXPECT_EQ(row.mode, a.additive ? ActionMode::Additive : ActionMode::Subtractive);
    EXPECT_EQ(row.process, a.path.process);
    EXPECT_EQ(row.setup, a.path.setup);
    const std::string instrument =
        a.path.process == Process::Deposition
            ? "head " + m.find_head_by_tool(a.path.tool_number)->name
            : "T" + std::to_string(a.path.tool_number) + " " + m.find_tool(a.path.tool_number)->name;
    EXPECT_EQ(row.instrument, instrument);
    // The heading comment opens the block; the blocks follow each other.
    ASSERT_GE(row.first_line, 1u);
    ASSERT_LE(row.last_line, p.lines.size());
    EXPECT_EQ(without_block_number(p.lines[row.first_line - 1]), "(" + row.heading() + ")");
    if (i > 0) {
      EXPECT_EQ(row.first_line, p.actions[i - 1].last_line + 1);
    }
  }
}

/// Every line inside an action's block belongs to it, the header and the end to none.
void expect_line_map(const PostedProgram& p) {
  for (std::uint32_t line = 1; line <= p.lines.size(); ++line) {
    std::optional<std::size_t> expected;
    for (std::size_t i = 0; i < p.actions.size(); ++i)
      if (p.actions[i].first_line <= line && line <= p.actions[i].last_line) expected = i;
    EXPECT_EQ(p.origins[line - 1].action, expected) << "line " << line << ": " << p.lines[line - 1];
    EXPECT_EQ(p.action_at(line), expected ? &p.actions[*expected] : nullptr);
  }
  EXPECT_EQ(p.action_at(0), nullptr);
  EXPECT_EQ(p.action_at(static_cast<std::uint32_t>(p.lines.size() + 1)), nullptr);
}

/// Every move's lines are in its action's block, in order, and the last of them is the
/// motion itself with the move's G code.
void expect_moves(const PostedProgram& p, const std::vector<ActionProgram>& actions) {
  for (std::size_t i = 0; i < actions.size(); ++i) {
    const auto& moves = actions[i].path.moves;
    std::vector<std::uint32_t> last_line_of(moves.size(), 0);
    std::size_t previous = 0;
    for (std::uint32_t line = 1; line <= p.lines.size(); ++line) {
      const LineOrigin& o = p.origins[line - 1];
      if (!o.move) continue;
      ASSERT_TRUE(o.action.has_value()) << "line " << line;
      if (*o.action != i) continue;
      ASSERT_LT(*o.move, moves.size());
      EXPECT_GE(*o.move, previous) << "line " << line;
      previous = *o.move;
      last_line_of[*o.move] = line;
    }
    for (std::size_t k = 0; k < moves.size(); ++k) {
      ASSERT_GT(last_line_of[k], 0u) << "action " << actions[i].action << " move " << k << " wrote no line";
      const std::string text = without_block_number(p.lines[last_line_of[k] - 1]);
      EXPECT_EQ(text.substr(0, text.find(' ')), g_code(moves[k].kind)) << text;
    }
  }
}

TEST(PostedProgram, EveryLineKnowsItsActionAndMove) {
  for (const char* file : {"hybrid-3axis.yaml", "multitask-b-axis.yaml"}) {
    SCOPED_TRACE(file);
    const Machine m = example(file);
    const auto actions = sample_actions(m);
    const PostedProgram p = post_program(actions, m);
    EXPECT_EQ(p.text(), write_program(actions, m));
    expect_table_agrees_with_actions(p, actions, m);
    expect_line_map(p);
    expect_moves(p, actions);
    // The header comes first, the program end last: neither belongs to an action.
    EXPECT_FALSE(p.origins.front().action.has_value());
    EXPECT_FALSE(p.origins.back().action.has_value());
    EXPECT_LT(p.actions.back().last_line, p.lines.size());
  }
}

TEST(PostedProgram, AStandaloneActionHasOneRow) {
  const Machine m = example("hybrid-3axis.yaml");
  const auto actions = sample_actions(m);
  const PostedProgram p = post_action(actions[2], m);
  EXPECT_EQ(p.text(), write_action(actions[2], m));
  expect_table_agrees_with_actions(p, {actions[2]}, m);
  expect_line_map(p);
  expect_moves(p, {actions[2]});
}

TEST(PostedProgram, TheTextAloneGivesTheSameTable) {
  for (const char* file : {"hybrid-3axis.yaml", "multitask-b-axis.yaml"}) {
    SCOPED_TRACE(file);
    const Machine m = example(file);
    const PostedProgram posted = post_program(sample_actions(m), m);
    const PostedProgram read = PostedProgram::from_text(posted.text());
    EXPECT_EQ(read.lines, posted.lines);
    EXPECT_EQ(read.text(), posted.text());
    ASSERT_EQ(read.actions.size(), posted.actions.size());
    for (std::size_t i = 0; i + 1 < read.actions.size(); ++i) EXPECT_EQ(read.actions[i], posted.actions[i]);
    // The text does not mark where the program's end begins: the last action runs to the end.
    ProgramAction last = posted.actions.back();
    last.last_line = static_cast<std::uint32_t>(posted.lines.size());
    EXPECT_EQ(read.actions.back(), last);
    for (std::size_t i = 0; i < read.lines.size(); ++i) {
      EXPECT_FALSE(read.origins[i].move.has_value());
      if (i < posted.actions.back().last_line) {
        EXPECT_EQ(read.origins[i].action, posted.origins[i].action) << i + 1;
      }
    }
  }
}

TEST(PostedProgram, OnlyOurHeadingsAreActions) {
  const PostedProgram p = PostedProgram::from_text(
      "(job)\r\n"
      "G21 G90\n"
      "(action 3: something else)\n"
      "G0 X1 (action 4: primitive P4, additive deposition with head ded in setup top)\n"
      "(action 5: primitive P5, additive deposition with head ded in setup top) trailing\n"
      "(action x: primitive P6, subtractive milling with T1 flat in setup top)\n"
      "N70 (action 7: primitive P7, subtractive milling with T1 10 mm flat in setup top)\n"
      "G1 X2 F100\n"
      "M2");
  ASSERT_EQ(p.lines.size(), 9u);
  EXPECT_EQ(p.lines[0], "(job)");
  ASSERT_EQ(p.actions.size(), 1u);
  const ProgramAction& a = p.actions[0];
  EXPECT_EQ(a.number, 7);
  EXPECT_EQ(a.primitive, "P7");
  EXPECT_EQ(a.mode, ActionMode::Subtractive);
  EXPECT_EQ(a.process, Process::Milling);
  EXPECT_EQ(a.instrument, "T1 10 mm flat");
  EXPECT_EQ(a.setup, "top");
  EXPECT_EQ(a.first_line, 7u);
  EXPECT_EQ(a.last_line, 9u);
  EXPECT_EQ(p.action_at(6), nullptr);
  EXPECT_EQ(p.action_at(8), &p.actions[0]);
  EXPECT_TRUE(PostedProgram::from_text("G21 G90\nG0 X10 Y10 Z50\nM2\n").actions.empty());
}

}  // namespace
