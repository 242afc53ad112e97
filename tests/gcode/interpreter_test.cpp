// The modal interpreter: what each code does to the machine, in work and machine
// coordinates, and the modal mistakes it refuses at line:column, leaving the state as it
// was so a checker or the simulator can go on.

#include "gcode/interpreter.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "config/machine_loader.hpp"
#include "gcode/check.hpp"

namespace {

using namespace hybridctl::gcode;
using hybridctl::config::Machine;
using hybridctl::config::parse_machine;

/// Envelope 400 x 300 x 300; G54 at (100, 50, 10), G55 at (300, 200, 20); a head T100 with
/// M64 P0 / M65 P0 and a power template; tools T1 and T2.
const Machine& machine() {
  static const Machine m = parse_machine(
      "name: test\n"
      "envelope:\n"
      "  X: {travel: [0, 400], max_feed: 12000, max_acceleration: 1000}\n"
      "  Y: {travel: [0, 300], max_feed: 12000, max_acceleration: 1000}\n"
      "  Z: {travel: [0, 300], max_feed: 6000, max_acceleration: 500}\n"
      "heads:\n"
      "  - {name: ded, process: ded-powder, bead: {width: 1.5, height: 0.75},\n"
      "     codes: {on: M64 P0, off: M65 P0, power: 'M68 E0 Q{power}', power_value: 800}}\n"
      "tools:\n"
      "  - {number: 1, type: flat, diameter: 10}\n"
      "  - {number: 2, type: ball, diameter: 6}\n"
      "setups:\n"
      "  - {name: top, work_offset: G54, work_origin: [100, 50, 10]}\n"
      "  - {name: bottom, approach: -Z, work_offset: G55, work_origin: [300, 200, 20]}\n",
      "test.yaml");
  return m;
}

void expect_near(const Vec3& a, const Vec3& b, double tol = 1e-9) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

/// Runs lines 1..n and returns the motions of the last line.
std::vector<Motion> run(Interpreter& in, const std::vector<std::string>& lines) {
  std::vector<Motion> last;
  int n = 0;
  for (const auto& l : lines) last = in.execute_line(l, ++n).motions;
  return last;
}

/// The error of the last line (all lines before must run).
std::string error_of(const std::vector<std::string>& lines) {
  Interpreter in(machine(), "t.ngc");
  int n = 0;
  for (std::size_t i = 0; i + 1 < lines.size(); ++i) in.execute_line(lines[i], ++n);
  try {
    in.execute_line(lines.back(), ++n);
  } catch (const GcodeError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected an error for: " << lines.back();
  return {};
}

void expect_error(const std::vector<std::string>& lines, const std::string& prefix, const std::string& words) {
  const std::string e = error_of(lines);
  EXPECT_EQ(e.rfind(prefix, 0), 0u) << lines.back() << " -> " << e;
  EXPECT_NE(e.find(words), std::string::npos) << lines.back() << " -> " << e;
}

TEST(Interpreter, StartsAtHomeInG54) {
  Interpreter in(machine());
  expect_near(in.state().position, {200, 150, 300});
  EXPECT_EQ(in.state().work_offset, 54);
  expect_near(in.state().offset, {100, 50, 10});
}

TEST(Interpreter, WorkCoordinatesPlusTheWorkOriginAreMachineCoordinates) {
  Interpreter in(machine());
  const auto m = run(in, {"G0 X10 Y20 Z30"});
  ASSERT_EQ(m.size(), 1u);
  EXPECT_EQ(m[0].kind, MotionKind::Rapid);
  EXPECT_EQ(m[0].line, 1);
  expect_near(m[0].to_work, {10, 20, 30});
  expect_near(m[0].to_machine, {110, 70, 40});
  expect_near(m[0].from_machine, {200, 150, 300});
  expect_near(m[0].from_work, {100, 100, 290});
  EXPECT_EQ(m[0].work_offset, 54);
}

TEST(Interpreter, MotionModeAndFeedAreModal) {
  Interpreter in(machine());
  run(in, {"G1 X1 F100"});
  const auto m = run(in, {"X2"});
  ASSERT_EQ(m.size(), 1u);
  EXPECT_EQ(m[0].kind, MotionKind::Feed);
  EXPECT_EQ(m[0].feed, 100.0);
  EXPECT_EQ(m[0].line, 1);               // run() numbers from 1 again
  EXPECT_TRUE(run(in, {"G1"}).empty());  // a motion code alone moves nothing
}

TEST(Interpreter, FeedMovesNeedAFeed) {
  expect_error({"G1 X10"}, "t.ngc:1:1: ", "G1 with zero feed rate; expected an F word greater than 0");
  expect_error({"G0 X1", "X5 G1 F0"}, "t.ngc:2:4: ", "zero feed rate");
  expect_error({"G3 X1 Y1 R1"}, "t.ngc:1:1: ", "G3 with zero feed rate");
  // Found by fuzz/gcode_fuzz (fuzz/corpus/gcode/regression-arc-words-only.ngc): a modal G2
  // line with only arc words was refused at column 0; its first arc word stands for the motion.
  expect_error({"G2", "R0"}, "t.ngc:2:1: ", "G2 with zero feed rate");
  expect_error({"G3", "  J2 I1"}, "t.ngc:2:3: ", "G3 with zero feed rate");
}

TEST(Interpreter, ModalGroupConflictsAndUnknownCodes) {
  expect_error({"G0 G1 X1 F10"}, "t.ngc:1:4: ", "two codes of the motion group");
  expect_error({"G90 G91"}, "t.ngc:1:5: ", "two codes of the distance mode group");
  expect_error({"G28"}, "t.ngc:1:1: ", "found G28, an unknown or unsupported G code; expected one of G0");
  expect_error({"G0 X1 M104"}, "t.ngc:1:7: ", "found M104, an unknown M code");
  expect_error({"M3 M5"}, "t.ngc:1:4: ", "same group");
  expect_error({"G93"}, "t.ngc:1:1: ", "inverse time");
  expect_error({"G41"}, "t.ngc:1:1: ", "cutter radius compensation is not supported");
}

TEST(Interpreter, AxisWordsNeedAMotionModeAndEveryWordAUse) {
  expect_error({"X10"}, "t.ngc:1:1: ", "no motion mode in effect");
  expect_error({"G0 X1", "G80", "Y2"}, "t.ngc:3:1: ", "no motion mode in effect");
  expect_error({"G0 X1 I5"}, "t.ngc:1:7: ", "found I5 with nothing on the line to use it");
  expect_error({"G0 X1 U5"}, "t.ngc:1:7: ", "does not use U words");
  expect_error({"M64"}, "t.ngc:1:1: ", "M64 with no P word");
  expect_error({"G4"}, "t.ngc:1:1: ", "G4 with no P word");
}

TEST(Interpreter, ArcsWithCentreOffsets) {
  Interpreter in(machine());
  const auto m = run(in, {"G0 X0 Y0 Z5", "G2 X10 Y0 I5 J0 F600"});
  ASSERT_EQ(m.size(), 1u);
  EXPECT_EQ(m[0].kind, MotionKind::ArcCw);
  EXPECT_EQ(m[0].plane, Plane::XY);
  expect_near(m[0].centre_work, {5, 0, 5});
  expect_near(m[0].centre_machine, {105, 50, 15});
  EXPECT_NEAR(arc_sweep(m[0]), M_PI, 1e-12);
  // G90.1: absolute centres, in work coordinates.
  const auto a = run(in, {"G90.1 G3 X0 Y0 I5 J0"});
  expect_near(a[0].centre_work, {5, 0, 5});
  EXPECT_EQ(a[0].kind, MotionKind::ArcCcw);
}

TEST(Interpreter, ArcsWithARadiusPickTheShortOrTheLongWay) {
  Interpreter in(machine());
  // Clockwise from (0,0) to (10,0) with R10: the short arc over the top, centre below.
  auto m = run(in, {"G0 X0 Y0 Z5", "G2 X10 Y0 R10 F600"});
  expect_near(m[0].centre_work, {5, -std::sqrt(75.0), 5}, 1e-9);
  EXPECT_LT(arc_sweep(m[0]), M_PI);
  // R-10: more than a half circle, centre above.
  m = run(in, {"G0 X0 Y0", "G2 X10 Y0 R-10"});
  expect_near(m[0].centre_work, {5, std::sqrt(75.0), 5}, 1e-9);
  EXPECT_GT(arc_sweep(m[0]), M_PI);
  expect_error({"G0 X0 Y0 Z5", "G2 X30 Y0 R10 F600"}, "t.ngc:2:11: ", "too small to reach the end point");
}

TEST(Interpreter, AFullCircleWithOffsetsAndNotWithR) {
  Interpreter in(machine());
  const auto m = run(in, {"G0 X0 Y0 Z5", "G3 X0 Y0 I10 F600"});
  ASSERT_EQ(m.size(), 1u);
  EXPECT_NEAR(arc_sweep(m[0]), 2 * M_PI, 1e-12);
  Vec3 lo, hi;
  motion_bounds(m[0], lo, hi);
  expect_near(lo, {100, 40, 15}, 1e-9);
  expect_near(hi, {120, 60, 15}, 1e-9);
  expect_error({"G0 X0 Y0 Z5", "G2 X0 Y0 R5 F600"}, "t.ngc:2:10: ", "ends where it starts");
  // Offsets and no axis words: a full circle where the tool is, as LinuxCNC runs it.
  const auto here = run(in, {"G2 I-10 F600"});
  ASSERT_EQ(here.size(), 1u);
  EXPECT_NEAR(arc_sweep(here[0]), 2 * M_PI, 1e-12);
  expect_error({"G0 X0 Y0 Z5", "G2 R5 F600"}, "t.ngc:2:1: ", "G2 with R and no X or Y word");
  expect_error({"G0 X0 Y0 Z5", "G2 X1 Y1 F600"}, "t.ngc:2:1: ", "G2 with no I, J or R");
  expect_error({"G0 X0 Y0 Z5", "G2 X1 I1 R1 F600"}, "t.ngc:2:10: ", "either a radius R or centre offsets");
}

TEST(Interpreter, ArcRadiusMismatchBeyondTolerance) {
  // Start radius 5, end radius 5.01: 0.01 mm apart.
  expect_error({"G0 X0 Y0 Z5", "G2 X10 Y0 I5.01 F600"},
               "t.ngc:2:11: ", "radius to end of arc differs from radius to start");
  // 0.0018 mm apart (and 0.036 %): within LinuxCNC-like tolerances.
  Interpreter in(machine());
  EXPECT_EQ(run(in, {"G0 X0 Y0 Z5", "G2 X10 Y0 I5.0009 F600"}).size(), 1u);
  // The relative check catches small arcs: radius 0.5 vs 0.5015 is 0.3 %.
  expect_error({"G0 X0 Y0 Z5", "G2 X1.0015 Y0 I0.5 F600"}, "t.ngc:2:15: ", "differs");
  expect_error({"G0 X0 Y0 Z5", "G2 X1 Y0 I0 J0 F600"}, "t.ngc:2:10: ", "zero radius");
}

TEST(Interpreter, ArcsInOtherPlanesUseTheirOffsets) {
  Interpreter in(machine());
  const auto m = run(in, {"G0 X0 Y0 Z5", "G18 G2 X10 Z5 I5 K0 F600"});
  ASSERT_EQ(m.size(), 1u);
  EXPECT_EQ(m[0].plane, Plane::ZX);
  expect_near(m[0].centre_work, {5, 0, 5});
  expect_error({"G0 X0 Y0 Z5", "G18 G2 X10 I5 J0 F600"}, "t.ngc:2:15: ", "found J with G2 in the ZX plane");
}

TEST(Interpreter, InchesAreConvertedToMillimetres) {
  Interpreter in(machine());
  auto m = run(in, {"G20 G0 X1 Y0 Z1"});
  expect_near(m[0].to_work, {25.4, 0, 25.4});
  m = run(in, {"G1 X2 F10"});
  EXPECT_NEAR(m[0].feed, 254.0, 1e-9);
  expect_near(m[0].to_work, {50.8, 0, 25.4}, 1e-9);
  m = run(in, {"G2 X0 Y0 I-1 F10"});  // back to work zero around (1, 0) in
  expect_near(m[0].centre_work, {25.4, 0, 25.4}, 1e-9);
  m = run(in, {"G21 G0 X1"});
  expect_near(m[0].to_work, {1, 0, 25.4}, 1e-9);
}

TEST(Interpreter, IncrementalMoves) {
  Interpreter in(machine());
  run(in, {"G0 X1 Y1 Z1"});
  auto m = run(in, {"G91 G0 X1"});
  expect_near(m[0].to_work, {2, 1, 1});
  m = run(in, {"X1 Y-2 Z0.5"});
  expect_near(m[0].to_work, {3, -1, 1.5});
  m = run(in, {"G90 X0"});
  expect_near(m[0].to_work, {0, -1, 1.5});
}

TEST(Interpreter, WorkOffsetsComeFromTheSetups) {
  Interpreter in(machine());
  auto m = run(in, {"G55 G0 X0 Y0 Z0"});
  expect_near(m[0].to_machine, {300, 200, 20});
  expect_near(m[0].to_work, {0, 0, 0});
  EXPECT_EQ(m[0].work_offset, 55);
  EXPECT_EQ(in.state().work_offset, 55);
  m = run(in, {"G54"});
  expect_near(in.state().work_position(), {200, 150, 10});
  expect_error({"G57"}, "t.ngc:1:1: ",
               "G57, a work offset no setup of machine 'test' uses; expected one of G54 (top), "
               "G55 (bottom)");
}

TEST(Interpreter, G53MovesInMachineCoordinatesForOneLine) {
  Interpreter in(machine());
  auto m = run(in, {"G0 X0 Y0 Z5", "G53 G0 Z300"});
  expect_near(m[0].to_machine, {100, 50, 300});
  EXPECT_EQ(m[0].work_offset, 53);
  m = run(in, {"G0 Z5"});  // back in G54
  expect_near(m[0].to_machine, {100, 50, 15});
  expect_error({"G0 X0 Y0 Z5", "G53 G2 X1 I1 F10"}, "t.ngc:2:1: ", "found G53 without G0 or G1");
  expect_error({"G91", "G53 G0 X1"}, "t.ngc:2:1: ", "incremental");
}

TEST(Interpreter, ToolChangeSpindleCoolantAndDeposition) {
  Interpreter in(machine());
  auto r = in.execute_line("T1 M6", 1);
  ASSERT_EQ(r.events.size(), 1u);
  EXPECT_EQ(r.events[0].kind, EventKind::ToolChange);
  EXPECT_EQ(r.events[0].tool, 1);
  EXPECT_EQ(in.state().tool, 1);
  in.execute_line("S8000 M3 M8", 2);
  auto m = in.execute_line("G1 X1 F100", 3).motions;
  ASSERT_EQ(m.size(), 1u);
  EXPECT_EQ(m[0].tool, 1);
  EXPECT_EQ(m[0].spindle, SpindleState::Cw);
  EXPECT_EQ(m[0].spindle_speed, 8000.0);
  EXPECT_TRUE(m[0].coolant);
  EXPECT_FALSE(m[0].deposition);

  in.execute_line("M9", 4);
  r = in.execute_line("T100 M6", 5);
  EXPECT_EQ(in.state().spindle, SpindleState::Off);  // M6 stops the spindle, as in LinuxCNC
  r = in.execute_line("M68 E0 Q800", 6);
  ASSERT_EQ(r.events.size(), 1u);
  EXPECT_EQ(r.events[0].kind, EventKind::AnalogOutput);
  EXPECT_EQ(r.events[0].value, 800.0);
  r = in.execute_line("M64 P0", 7);
  ASSERT_EQ(r.events.size(), 1u);
  EXPECT_EQ(r.events[0].kind, EventKind::DepositionOn);
  EXPECT_EQ(r.events[0].index, 0);
  EXPECT_EQ(r.events[0].tool, 100);
  m = in.execute_line("G1 X2", 8).motions;
  EXPECT_TRUE(m[0].deposition);
  EXPECT_EQ(m[0].tool, 100);
  EXPECT_FALSE(m[0].coolant);
  r = in.execute_line("M65 P0 G1 X3", 9);
  EXPECT_EQ(r.events[0].kind, EventKind::DepositionOff);
  EXPECT_FALSE(r.motions[0].deposition);  // codes act before the line's motion
  // An output that is no head's code is a plain digital output.
  r = in.execute_line("M64 P3", 10);
  EXPECT_EQ(r.events[0].kind, EventKind::DigitalOutput);
  EXPECT_EQ(r.events[0].index, 3);
}

TEST(Interpreter, ProgramStopsCarryTheOperatorMessage) {
  Interpreter in(machine());
  in.execute_line("(MSG, flip the part onto the soft jaws)", 1);
  auto r = in.execute_line("M0", 2);
  ASSERT_EQ(r.events.size(), 1u);
  EXPECT_EQ(r.events[0].kind, EventKind::ProgramStop);
  EXPECT_TRUE(r.events[0].after_motion);
  EXPECT_EQ(r.events[0].message, "flip the part onto the soft jaws");
  r = in.execute_line("M1 (check the bead)", 3);
  EXPECT_EQ(r.events[0].kind, EventKind::OptionalStop);
  EXPECT_EQ(r.events[0].message, "check the bead");
  r = in.execute_line("M0", 4);  // the comment before was not on a comment-only line
  EXPECT_EQ(r.events[0].message, "");
}

TEST(Interpreter, DwellAndProgramEnd) {
  Interpreter in(machine());
  auto r = in.execute_line("G4 P2.5", 1);
  ASSERT_EQ(r.events.size(), 1u);
  EXPECT_EQ(r.events[0].kind, EventKind::Dwell);
  EXPECT_EQ(r.events[0].value, 2.5);
  r = in.execute_line("M2", 2);
  EXPECT_EQ(r.events[0].kind, EventKind::ProgramEnd);
  EXPECT_TRUE(in.state().ended);
  EXPECT_NO_THROW(in.execute_line("%", 3));
  expect_error({"M30", "G0 X1"}, "t.ngc:2:1: ", "found words after the program end");
}

TEST(Interpreter, FanucDwellsAreInSecondsWithXAndMillisecondsWithP) {
  const Machine m = hybridctl::config::load_machine(std::string(HYBRIDCTL_SOURCE_DIR) +
                                                    "/examples/machines/multitask-b-axis.yaml");
  Interpreter in(m);
  auto r = in.execute_line("G4 P1500", 1);
  ASSERT_EQ(r.events.size(), 1u);
  EXPECT_EQ(r.events[0].value, 1.5);
  r = in.execute_line("G4 X2.", 2);
  ASSERT_EQ(r.events.size(), 1u);
  EXPECT_EQ(r.events[0].value, 2.0);
  EXPECT_TRUE(r.motions.empty());  // X is the dwell here, not an axis
}

TEST(Interpreter, TheMachinesOwnMCodes) {
  const Machine m =
      hybridctl::config::load_machine(std::string(HYBRIDCTL_SOURCE_DIR) + "/examples/machines/multitask-b-axis.yaml");
  Interpreter in(m);
  in.execute_line("T1 M6", 1);
  auto r = in.execute_line("S6000 M203", 2);  // this mill-turn's milling spindle
  ASSERT_EQ(r.events.size(), 1u);
  EXPECT_EQ(r.events[0].kind, EventKind::SpindleStart);
  EXPECT_EQ(in.state().spindle, SpindleState::Cw);
  in.execute_line("M205", 3);
  EXPECT_EQ(in.state().spindle, SpindleState::Off);
  // The arc head switches with M64 P1; the DED head with M64 P0.
  r = in.execute_line("M64 P1", 4);
  EXPECT_EQ(r.events[0].kind, EventKind::DepositionOn);
  EXPECT_EQ(r.events[0].index, 0);
  EXPECT_EQ(r.events[0].tool, 100);
  auto motions = in.execute_line("G0 B90 C45", 5).motions;
  ASSERT_EQ(motions.size(), 1u);
  EXPECT_EQ(motions[0].to_rotary, (Rotary{0, 90, 45}));
}

TEST(Interpreter, ABadLineLeavesTheStateAsItWas) {
  Interpreter in(machine());
  in.execute_line("G0 X1 Y2 Z3", 1);
  const ModalState before = in.state();
  EXPECT_THROW(in.execute_line("G91 G20 T5 M6 F10 G1 X1 Q", 2), GcodeError);
  EXPECT_THROW(in.execute_line("G91 G20 T5 M6 F10 G2 X9 I1", 3), GcodeError);
  const ModalState& after = in.state();
  expect_near(after.position, before.position);
  EXPECT_EQ(after.absolute, before.absolute);
  EXPECT_EQ(after.inches, before.inches);
  EXPECT_EQ(after.tool, before.tool);
  EXPECT_EQ(after.selected_tool, before.selected_tool);
  EXPECT_EQ(after.feed, before.feed);
  EXPECT_EQ(after.motion, before.motion);
}

TEST(Interpreter, StreamingLineByLineEqualsTheWholeFile) {
  const std::string text = "G21 G90\nT1 M6\nS1000 M3\nG0 X0 Y0 Z5\nG1 Z1 F100\nG2 X10 Y0 I5\nG0 Z20\nM2\n";
  const Program whole = interpret(text, machine(), "t.ngc");
  EXPECT_EQ(whole.lines, 8);
  Interpreter in(machine(), "t.ngc");
  std::vector<Motion> streamed;
  for_each_line(text, [&](std::string_view l, int n) {
    const auto& r = in.execute_line(l, n);
    streamed.insert(streamed.end(), r.motions.begin(), r.motions.end());
  });
  ASSERT_EQ(whole.motions.size(), streamed.size());
  ASSERT_EQ(whole.motions.size(), 4u);
  for (std::size_t i = 0; i < streamed.size(); ++i) {
    EXPECT_EQ(whole.motions[i].line, streamed[i].line);
    expect_near(whole.motions[i].to_machine, streamed[i].to_machine);
  }
  EXPECT_EQ(whole.motions[2].line, 6);
  EXPECT_EQ(whole.events.back().kind, EventKind::ProgramEnd);
}

TEST(Interpreter, HostileLinesOnlyEverThrowGcodeError) {
  // Mutations of valid lines and random bytes: each either runs or is a GcodeError.
  const std::vector<std::string> seeds = {"G0 X10 Y-2.5 Z3", "G2 X10 Y0 I5 J0 F600", "G3 X1 Y1 R-2 F10",
                                          "G18 G2 X1 Z1 K1 F5", "T100 M6 M64 P0", "G53 G0 Z300",
                                          "G20 G91 G1 X1 F1", "M68 E0 Q800", "G4 P1", "G55 G0 X0"};
  std::mt19937 rng(1234);
  const std::string alphabet = "GMXYZIJKRFPSTEQHNOABC0123456789.-+ ()%;#/\t\x01\xff";
  int errors = 0, ran = 0;
  for (int i = 0; i < 20000; ++i) {
    std::string line = seeds[rng() % seeds.size()];
    const int edits = 1 + static_cast<int>(rng() % 4);
    for (int e = 0; e < edits; ++e) {
      const std::size_t at = line.empty() ? 0 : rng() % line.size();
      const char c = alphabet[rng() % alphabet.size()];
      switch (rng() % 3) {
        case 0: line.insert(at, 1, c); break;
        case 1: if (!line.empty()) line.erase(at, 1); break;
        default: if (!line.empty()) line[at] = c; break;
      }
    }
    if (i % 10 == 0) line = "X" + std::string(400, '9') + "." + std::string(400, '9');  // beyond a double
    Interpreter in(machine(), "fuzz.ngc");
    try {
      in.execute_line("G0 X1 Y1 Z5 F100", 1);
      in.execute_line(line, 2);
      ++ran;
    } catch (const GcodeError& e) {
      EXPECT_EQ(std::string(e.what()).rfind("fuzz.ngc:2:", 0), 0u) << e.what();
      ++errors;
    }
  }
  EXPECT_GT(errors, 1000);
  EXPECT_GT(ran, 100);
}

TEST(Interpreter, HeadCodesTheInterpreterCannotRecogniseAreRefused) {
  Machine m = machine();
  m.heads[0].codes.on = "G1 X1";
  EXPECT_THROW(Interpreter{m}, hybridctl::InputError);
  // An output number beyond an int was converted to one (undefined behaviour, found with
  // UBSan by fuzz/gcode_fuzz); a fraction was cut off.
  for (const char* on : {"M64 P99999999999", "M64 P1.5"}) {
    m.heads[0].codes.on = on;
    try {
      Interpreter in(m);
      ADD_FAILURE() << on << " was taken";
    } catch (const hybridctl::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("heads[0].codes.on '" + std::string(on) +
                                           "': expected the output number P to be a whole number from 0 to 99999"),
                std::string::npos)
          << e.what();
    }
  }
}

TEST(Interpreter, NumberWordsBeyondAnIntAreRefusedAtTheirColumn) {
  // Found by fuzz/gcode_fuzz (fuzz/corpus/gcode/regression-number-words.ngc): T, H, P and
  // E values beyond an int were converted to one, undefined behaviour that UBSan reports.
  expect_error({"M64 P100000000000"}, "t.ngc:1:5: ", "found P100000000000 with M64; expected an output number, a whole number from 0 to 99999");
  expect_error({"M62 P100000"}, "t.ngc:1:5: ", "a whole number from 0 to 99999");
  expect_error({"M68 E10000000000 Q1"}, "t.ngc:1:5: ", "found E10000000000; expected an analog output number, a whole number from 0 to 99999");
  expect_error({"G43 H10000000000"}, "t.ngc:1:5: ", "found H10000000000; expected a tool number, a whole number from 0 to 99999");
  expect_error({"T10000000000 M6"}, "t.ngc:1:1: ", "found T10000000000; expected a tool number, a whole number from 0 to 99999");
}

}  // namespace
