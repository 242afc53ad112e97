// The post-processor, checked the way PrusaSlicer checks its G-code: parse what we wrote
// with our own interpreter and assert invariants (the toolpath comes back move for move,
// deposition is on exactly where the toolpath says, tools and setups change where they
// should), plus the dialects' shapes and the refusal to write anything that would leave
// the envelope.

#include "gcode/post.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "config/machine_loader.hpp"
#include "gcode/interpreter.hpp"
#include "gcode/program.hpp"
#include "gcode/tool_table.hpp"
#include "sample_programs.hpp"

namespace {

namespace fs = std::filesystem;
using namespace hybridctl::gcode;
using hybridctl::config::Machine;
using hybridctl::gcode::samples::sample_actions;

Machine example(const std::string& name) {
  return hybridctl::config::load_machine(std::string(HYBRIDCTL_SOURCE_DIR) + "/examples/machines/" + name);
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  for_each_line(text, [&](std::string_view l, int) { out.emplace_back(l); });
  return out;
}

int count_lines(const std::string& text, const std::string& line) {
  int n = 0;
  for (const auto& l : lines_of(text)) n += l == line;
  return n;
}

bool near(const Vec3& a, const Vec3& b, double tol = 1e-4) {
  return std::abs(a.x - b.x) <= tol && std::abs(a.y - b.y) <= tol && std::abs(a.z - b.z) <= tol;
}

MotionKind kind_of(MoveKind k) {
  switch (k) {
    case MoveKind::Rapid: return MotionKind::Rapid;
    case MoveKind::Feed: return MotionKind::Feed;
    case MoveKind::ArcCw: return MotionKind::ArcCw;
    case MoveKind::ArcCcw: return MotionKind::ArcCcw;
  }
  return MotionKind::Rapid;
}

bool same(const Motion& m, const PathMove& p, bool additive) {
  if (m.kind != kind_of(p.kind) || !near(m.to_work, p.to)) return false;
  if (p.kind != MoveKind::Rapid && std::abs(m.feed - p.feed) > 1e-9) return false;
  if (m.is_arc() && !near(Vec3{m.centre_work.x, m.centre_work.y, 0}, Vec3{p.centre.x, p.centre.y, 0})) return false;
  return m.deposition == (additive && p.process_on);
}

/// Every action's moves come back, in order, as consecutive motions in the action's
/// setup, with its tool, at its feeds, with deposition on exactly where process_on says.
void expect_round_trip(const std::vector<ActionProgram>& actions, const Machine& machine, const std::string& text) {
  const Program program = interpret(text, machine, "post.ngc");
  std::size_t from = 0;
  for (const auto& a : actions) {
    const auto& moves = a.path.moves;
    const int offset = machine.find_setup(a.path.setup)->work_offset;
    bool found = false;
    for (std::size_t i = from; i + moves.size() <= program.motions.size() && !found; ++i) {
      bool all = true;
      for (std::size_t k = 0; k < moves.size() && all; ++k) {
        const Motion& m = program.motions[i + k];
        all = same(m, moves[k], a.additive) && m.tool == a.path.tool_number && m.work_offset == offset &&
              (a.additive ? m.spindle == SpindleState::Off : m.spindle == SpindleState::Cw);
      }
      if (all) {
        found = true;
        from = i + moves.size();
      }
    }
    EXPECT_TRUE(found) << "action " << a.action << "'s moves are not in the program:\n" << text;
  }
  ASSERT_FALSE(program.events.empty());
  EXPECT_EQ(program.events.back().kind, EventKind::ProgramEnd);
  // Nothing deposits outside the toolpath's deposition moves.
  int depositing = 0, planned = 0;
  for (const Motion& m : program.motions) depositing += m.deposition;
  for (const auto& a : actions)
    for (const auto& p : a.path.moves) planned += a.additive && p.process_on;
  EXPECT_EQ(depositing, planned);
}

TEST(PostNumbers, FourDecimalsTrimmedNoNegativeZero) {
  EXPECT_EQ(format_number(1.23456), "1.2346");
  EXPECT_EQ(format_number(2.0), "2");
  EXPECT_EQ(format_number(-1.5), "-1.5");
  EXPECT_EQ(format_number(-0.00001), "0");
  EXPECT_EQ(format_number(-0.0), "0");
  EXPECT_EQ(format_number(0.1 + 0.2), "0.3");
  EXPECT_EQ(format_number(123456.78901), "123456.789");
  EXPECT_EQ(format_number(2.00004), "2");
  EXPECT_EQ(format_number(-2.00006), "-2.0001");
  EXPECT_EQ(format_number(10, true), "10.");
  EXPECT_EQ(format_number(-0.00001, true), "0.");
  EXPECT_EQ(format_number(2.5, true), "2.5");
}

TEST(PostRs274ngc, HeaderActionsAndEnd) {
  const Machine m = example("hybrid-3axis.yaml");
  const auto actions = sample_actions(m);
  PostOptions options;
  options.program_name = "bracket plan 1";
  const std::string text = write_program(actions, m, options);
  const auto lines = lines_of(text);
  ASSERT_GT(lines.size(), 20u);
  EXPECT_EQ(lines[0], "(bracket plan 1)");
  EXPECT_NE(text.find("\nG21 G90 G17 G94 G40 G49 G80\nG54\n"), std::string::npos) << text;
  EXPECT_EQ(lines.back(), "M2");
  EXPECT_EQ(text.find('%'), std::string::npos);
  EXPECT_EQ(write_program(actions, m, options), text) << "output must be deterministic";
  // Per action: a comment block with number, primitive, mode, volume and time.
  EXPECT_NE(text.find("(action 1: primitive P1, additive deposition with head ded in setup top)"), std::string::npos)
      << text;
  EXPECT_NE(text.find("(action 2: primitive P2, subtractive milling with T1 10 mm flat rougher in setup top)"),
            std::string::npos);
  EXPECT_NE(text.find("(volume 1234.5 mm3, toolpath motion "), std::string::npos);
  // Tool changes with length compensation, the spindle after the change, M5 before the head.
  EXPECT_NE(text.find("\nT100 M6\nG43 H100\nM68 E0 Q800\n"), std::string::npos) << text;
  EXPECT_NE(text.find("\nT1 M6\nG43 H1\nS8000 M3\n"), std::string::npos) << text;
  EXPECT_NE(text.find("\nM5\nG53 G0 Z300\nT100 M6\n"), std::string::npos) << text;
  // The setup change: a stop with the operator's message, then the new work offset.
  EXPECT_NE(text.find("(MSG, setup bottom: part flipped on soft jaws - refixture the part for -Z, then cycle start)\n"
                      "M0\nG55\n"),
            std::string::npos)
      << text;
  // Deposition switched where process_on changes: 2 layers x 2 actions; power once per action.
  EXPECT_EQ(count_lines(text, "M64 P0"), 4);
  EXPECT_EQ(count_lines(text, "M65 P0"), 4);
  EXPECT_EQ(count_lines(text, "M68 E0 Q800"), 2);
  expect_round_trip(actions, m, text);
}

TEST(PostRs274ngc, FeedsAreWrittenOnlyWhenTheyChange) {
  const Machine m = example("hybrid-3axis.yaml");
  const auto actions = sample_actions(m);
  const std::string text = write_program(actions, m);
  int written = 0;
  for (const auto& l : lines_of(text)) written += l.find(" F") != std::string::npos;
  // Feed changes along the non-rapid moves, in program order.
  int changes = 0;
  double last = -1;
  for (const auto& a : actions)
    for (const auto& p : a.path.moves)
      if (p.kind != MoveKind::Rapid && p.feed != last) {
        ++changes;
        last = p.feed;
      }
  EXPECT_EQ(written, changes) << text;
}

// A pass at its own spindle speed (a finishing pass): S before it and back after, and the
// controller runs each move at the speed its pass asks for.
TEST(PostRs274ngc, APassAtItsOwnSpindleSpeedChangesSAndBack) {
  const Machine m = example("hybrid-3axis.yaml");
  std::vector<ActionProgram> actions = sample_actions(m);
  ActionProgram& milling = actions[1];  // with T1
  const double rough = m.find_tool(milling.path.tool_number)->spindle_speed;
  std::size_t fast = 0;
  for (std::size_t k = 0; k < milling.path.moves.size(); ++k)
    if (milling.path.moves[k].kind != MoveKind::Rapid && k % 2 == 0) milling.path.moves[k].spindle = 12345, ++fast;
  ASSERT_GT(fast, 0u);
  const std::string text = write_program(actions, m);
  EXPECT_GE(count_lines(text, "S12345"), 1) << text;
  EXPECT_GE(count_lines(text, "S" + std::to_string(std::lround(rough))), 1) << text;
  const Program program = interpret(text, m, "post.ngc");
  std::size_t at_fast = 0;
  for (const Motion& motion : program.motions)
    if (motion.kind != MotionKind::Rapid && motion.spindle_speed == 12345) ++at_fast;
  EXPECT_EQ(at_fast, fast);
  expect_round_trip(actions, m, text);
}

TEST(PostRs274ngc, RotarySetupChangeOnTheBAxisMachine) {
  Machine m = example("multitask-b-axis.yaml");
  m.gcode.dialect = hybridctl::config::Dialect::Rs274ngc;
  m.gcode.m_codes = {};  // LinuxCNC's codes, not this mill-turn's M203
  const auto actions = sample_actions(m);
  const std::string text = write_program(actions, m);
  // The first setup's rotary position is set before any work, the second's replaces the stop.
  EXPECT_NE(text.find("\nG0 B0 C0\n"), std::string::npos) << text;
  EXPECT_NE(text.find("\nG0 B90 C0\nG55\n"), std::string::npos) << text;
  EXPECT_EQ(text.find("M0\n"), std::string::npos) << text;
  // The arc head switches output 1, the DED head output 0 with its power.
  EXPECT_EQ(count_lines(text, "M64 P1"), 2);
  EXPECT_EQ(count_lines(text, "M64 P0"), 2);
  EXPECT_EQ(count_lines(text, "M68 E0 Q1200"), 1);
  expect_round_trip(actions, m, text);
}

TEST(PostFanuc, PercentONumberAndNNumbers) {
  const Machine m = example("multitask-b-axis.yaml");  // dialect fanuc, O2000, M203 spindle
  const auto actions = sample_actions(m);
  const std::string text = write_program(actions, m);
  const auto lines = lines_of(text);
  ASSERT_GT(lines.size(), 10u);
  EXPECT_EQ(lines.front(), "%");
  EXPECT_EQ(lines[1], "O2000 (hybridctl)");
  EXPECT_EQ(lines.back(), "%");
  int expected_n = 10;
  for (std::size_t i = 2; i + 1 < lines.size(); ++i) {
    const std::string prefix = "N" + std::to_string(expected_n) + " ";
    ASSERT_EQ(lines[i].rfind(prefix, 0), 0u) << "line " << i + 1 << ": " << lines[i];
    expected_n += 10;
  }
  EXPECT_NE(lines[lines.size() - 2].find(" M30"), std::string::npos);
  EXPECT_NE(text.find(" S6000 M203\n"), std::string::npos) << text;  // the machine's spindle code
  // Whole numbers keep their decimal point: X25. not X25 (which some controls read as 25 µm).
  EXPECT_TRUE(std::regex_search(text, std::regex(" G0 X25\\. Z5\\.\n"))) << text;
  EXPECT_FALSE(std::regex_search(text, std::regex("[XYZIJF]-?[0-9]+( |\n)"))) << text;
  // Our interpreter reads it back the same.
  expect_round_trip(actions, m, text);
  // A single action is its own program with its own number.
  const std::string one = write_action(actions[1], m);
  EXPECT_EQ(lines_of(one)[1], "O2002 (hybridctl)");
}

TEST(PostRefusals, AMoveOutsideTheEnvelopeIsRefusedAndNothingIsWritten) {
  const Machine m = example("hybrid-3axis.yaml");  // X travel [0, 400], work zero at X 200
  auto actions = sample_actions(m);
  actions[1].path.moves[3].to.x = -250;  // machine X -50
  actions[1].path.moves[3].kind = MoveKind::Feed;
  try {
    write_program(actions, m);
    FAIL() << "expected a refusal";
  } catch (const hybridctl::InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("action 2 (P2, SM-max 10 mm flat rougher @ top), move 4 of 7 (generated line "),
              std::string::npos)
        << what;
    EXPECT_NE(what.find(": G1 X-250"), std::string::npos) << what;
    EXPECT_NE(what.find("X reaches -50, below the X travel [0, 400]"), std::string::npos) << what;
    EXPECT_NE(what.find("nothing was written"), std::string::npos) << what;
  }
  const fs::path dir = fs::temp_directory_path() / ("hybridctl-post-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  EXPECT_THROW(write_program_files(dir, "plan", actions, m), hybridctl::InputError);
  EXPECT_TRUE(fs::is_empty(dir)) << "a refused program left files behind";
  // The same actions inside the envelope are written: the program and one file per action.
  const ProgramFiles files = write_program_files(dir, "plan", sample_actions(m), m);
  EXPECT_EQ(files.program, dir / "plan.ngc");
  ASSERT_EQ(files.actions.size(), 4u);
  EXPECT_EQ(files.actions[0], dir / "plan-action-01.ngc");
  for (const auto& f : files.actions) EXPECT_TRUE(fs::exists(f)) << f;
  fs::remove_all(dir);
}

TEST(PostRefusals, AnApproachThatLeavesTheEnvelopeNamesTheGeneratedStep) {
  const Machine m = example("hybrid-3axis.yaml");
  auto actions = sample_actions(m);
  actions[0].path.start.z = 400;  // above the Z travel
  try {
    write_program(actions, m);
    FAIL();
  } catch (const hybridctl::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("action 1 (P1, U-AM ded @ top), approach to the path start"),
              std::string::npos)
        << e.what();
  }
}

TEST(PostRefusals, PrinterCodesAreNotWrittenForLinuxCnc) {
  Machine m = example("hybrid-3axis.yaml");
  m.heads[0].codes.on = "M104 S200";
  try {
    write_program(sample_actions(m), m);
    FAIL();
  } catch (const hybridctl::InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("heads[0] (ded).codes.on 'M104 S200' is not a LinuxCNC output code"), std::string::npos)
        << what;
  }
  Machine mill_turn = example("multitask-b-axis.yaml");
  mill_turn.gcode.dialect = hybridctl::config::Dialect::Rs274ngc;
  try {
    write_program(sample_actions(mill_turn), mill_turn);
    FAIL();
  } catch (const hybridctl::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("gcode.m_codes.spindle_cw M203 is not the code LinuxCNC runs for it"),
              std::string::npos)
        << e.what();
  }
}

// A machine file whose programs could never be posted is refused when it is loaded, at
// the key's line and column, not after planning has run.
TEST(PostRefusals, AMachineFileThatCannotPostIsRefusedAtLoadAtItsKey) {
  std::string text = hybridctl::config::read_machine_text(std::string(HYBRIDCTL_SOURCE_DIR) + "/examples/machines/multitask-b-axis.yaml");
  EXPECT_NO_THROW(parse_postable_machine(text, "multitask-b-axis.yaml")) << "the fanuc dialect runs M203";
  const auto dialect = text.find("dialect: fanuc");
  ASSERT_NE(dialect, std::string::npos);
  text.replace(dialect, 14, "dialect: rs274ngc");
  // The line and column of the spindle code's value in the file.
  const auto value = text.find("M203");
  const int line = 1 + int(std::count(text.begin(), text.begin() + std::ptrdiff_t(value), '\n'));
  const int column = int(value - text.rfind('\n', value));
  try {
    parse_postable_machine(text, "b-axis-for-linuxcnc.yaml");
    FAIL() << "loaded";
  } catch (const hybridctl::config::MachineFileError& e) {
    ASSERT_EQ(e.diagnostics().size(), 1u);
    const auto& d = e.diagnostics()[0];
    EXPECT_EQ(d.file, "b-axis-for-linuxcnc.yaml");
    EXPECT_EQ(d.line, line);
    EXPECT_EQ(d.column, column);
    EXPECT_NE(d.message.find("gcode.m_codes.spindle_cw M203 is not the code LinuxCNC runs for it; expected M3"), std::string::npos)
        << d.message;
  }
  // A head's code: at the head's own key, in a flow mapping.
  std::string head = hybridctl::config::read_machine_text(std::string(HYBRIDCTL_SOURCE_DIR) + "/examples/machines/hybrid-3axis.yaml");
  const auto on = head.find("M64 P0");
  ASSERT_NE(on, std::string::npos);
  head.replace(on, 6, "M104 S200");
  try {
    parse_postable_machine(head, "printer-codes.yaml");
    FAIL() << "loaded";
  } catch (const hybridctl::config::MachineFileError& e) {
    const auto& d = e.diagnostics()[0];
    EXPECT_EQ(d.line, 1 + int(std::count(head.begin(), head.begin() + std::ptrdiff_t(on), '\n')));
    EXPECT_NE(d.message.find(".codes.on 'M104 S200' is not a LinuxCNC output code"), std::string::npos) << d.message;
  }
}

TEST(PostRefusals, UnknownToolsSetupsAndZeroFeeds) {
  const Machine m = example("hybrid-3axis.yaml");
  auto actions = sample_actions(m);
  actions[1].path.tool_number = 9;
  EXPECT_THROW(write_program(actions, m), hybridctl::InputError);
  actions = sample_actions(m);
  actions[2].path.setup = "sideways";
  EXPECT_THROW(write_program(actions, m), hybridctl::InputError);
  actions = sample_actions(m);
  actions[1].path.moves[1].feed = 0;
  try {
    write_program(actions, m);
    FAIL();
  } catch (const hybridctl::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("move 2 of 7"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("zero feed rate"), std::string::npos) << e.what();
  }
}

TEST(PostActions, OneActionIsAStandaloneProgram) {
  const Machine m = example("hybrid-3axis.yaml");
  const auto actions = sample_actions(m);
  const std::string text = write_action(actions[2], m);
  EXPECT_NE(text.find("\nG55\n"), std::string::npos) << text;  // its own setup from the start
  EXPECT_NE(text.find("\nT2 M6\n"), std::string::npos);
  EXPECT_EQ(text.find("T1 M6"), std::string::npos);
  EXPECT_EQ(text.find("M0\n"), std::string::npos);  // no setup change within it
  expect_round_trip({actions[2]}, m, text);
  PostOptions coolant;
  coolant.coolant = true;
  const std::string wet = write_action(actions[1], m, coolant);
  EXPECT_NE(wet.find("\nS8000 M3\nM8\n"), std::string::npos) << wet;
  EXPECT_NE(wet.find("\nM9\n"), std::string::npos) << wet;
}

// Comments carry plan expressions ("∪", "−") and units ("mm³", "°") from the planner and
// the machine file; in the program they are plain ASCII, spelled out, in both dialects.
TEST(PostComments, PlainAsciiInEveryDialect) {
  for (const std::string machine_file : {"hybrid-3axis.yaml", "multitask-b-axis.yaml"}) {
    SCOPED_TRACE(machine_file);
    Machine m = example(machine_file);
    m.setups.at(1).description = "flipped 180\u00B0 on soft jaws \u2014 \u00F880 chuck";
    m.setups.at(1).manual_refixture = true;  // so the stop's message is written in both dialects
    auto actions = sample_actions(m);
    actions[0].label = "repair deposit near the missing 12 mm\u00B3 \u2713";
    actions[0].path.moves[1].comment = "layer 1, 0.5 mm\u00B2 at 45\u00B0";
    actions[1].path.warnings.push_back("3.2 mm\u00B3 left \u2264 0.1 mm from the design \xff");
    PostOptions options;
    options.program_name = "plan-1 ((P1 \u222A P9) \u2212 P7)";
    const std::string text = write_program(actions, m, options);
    const auto lines = lines_of(text);
    for (std::size_t i = 0; i < lines.size(); ++i)
      for (const char c : lines[i])
        ASSERT_TRUE(static_cast<unsigned char>(c) >= 0x20 && static_cast<unsigned char>(c) < 0x7f)
            << "line " << i + 1 << " is not plain ASCII: " << lines[i];
    const bool fanuc = m.gcode.dialect == hybridctl::config::Dialect::Fanuc;
    EXPECT_EQ(lines.at(fanuc ? 1 : 0), fanuc ? "O2000 (plan-1 [[P1 + P9] - P7])" : "(plan-1 [[P1 + P9] - P7])");
    EXPECT_NE(text.find("(repair deposit near the missing 12 mm3 ?)\n"), std::string::npos) << text;
    EXPECT_NE(text.find("(layer 1, 0.5 mm2 at 45 deg)\n"), std::string::npos) << text;
    EXPECT_NE(text.find("(warning: 3.2 mm3 left <= 0.1 mm from the design ?)\n"), std::string::npos) << text;
    EXPECT_NE(text.find(": flipped 180 deg on soft jaws - dia 80 chuck - refixture the part"), std::string::npos)
        << text;
    expect_round_trip(actions, m, text);
  }
}

TEST(PostComments, CommentTextSpellsOutWhatItCanAndMarksTheRest) {
  EXPECT_EQ(comment_text("((P1 \u222A P2) \u2212 P3)"), "[[P1 + P2] - P3]");
  EXPECT_EQ(comment_text("12 mm\u00B3, 30\u00B0"), "12 mm3, 30 deg");
  EXPECT_EQ(comment_text("a \u2713 b"), "a ? b");        // one '?' per character
  EXPECT_EQ(comment_text("a \xe2\x88 b \xff"), "a ? b ?");  // a cut-off sequence, a stray byte
  EXPECT_EQ(comment_text("\xc0\xb3"), "??");                  // an overlong '3' is not a '3'
  EXPECT_EQ(comment_text("tab\there\nnew (line)"), "tab here new [line]");
}

TEST(ToolTable, EveryToolAndHeadInLinuxCncFormat) {
  const Machine m = example("multitask-b-axis.yaml");
  EXPECT_EQ(linuxcnc_tool_table(m),
            "T1 P1 D16 Z0 ;16 mm flat rougher\n"
            "T2 P2 D10 Z0 ;10 mm bull nose\n"
            "T3 P3 D8 Z0 ;8 mm ball finisher\n"
            "T4 P4 D4 Z0 ;4 mm flat detail\n"
            "T12 P12 D12 Z0 ;12 mm flat\n"
            "T100 P100 D6 Z0 ;head arc (wire-arc)\n"
            "T101 P101 D1.2 Z0 ;head ded (ded-powder)\n");
}

}  // namespace
