// `gcode check` semantics: envelope violations (including an arc's bulge), unknown tool
// numbers, deposition and spindle misuse, errors collected line by line, and a time
// estimate that matches hand-computed trapezoids.

#include "gcode/check.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "config/machine_loader.hpp"

namespace {

using namespace hybridctl::gcode;
using hybridctl::config::Machine;
using hybridctl::config::parse_machine;

/// X, Y: 12000 mm/min (200 mm/s), 1000 mm/s²; Z: 6000 mm/min (100 mm/s), 500 mm/s².
constexpr const char* kLinearAxes =
    "name: test\n"
    "envelope:\n"
    "  X: {travel: [0, 400], max_feed: 12000, max_acceleration: 1000}\n"
    "  Y: {travel: [0, 300], max_feed: 12000, max_acceleration: 1000}\n"
    "  Z: {travel: [0, 300], max_feed: 6000, max_acceleration: 500}\n";

/// Those axes and a B axis; G54 at (100, 50, 10).
const Machine& machine() {
  static const Machine m = parse_machine(
      std::string(kLinearAxes) +
      "  B: {range: [-90, 90], max_feed: 3600, max_acceleration: 360}\n"
      "heads:\n"
      "  - {name: ded, process: ded-powder, bead: {width: 1.5, height: 0.75}}\n"
      "tools:\n"
      "  - {number: 1, type: flat, diameter: 10}\n"
      "setups:\n"
      "  - {name: top, work_offset: G54, work_origin: [100, 50, 10]}\n",
      "test.yaml");
  return m;
}

CheckReport check(const std::string& text) { return check_program(text, machine(), "c.ngc"); }

/// The time of a program of one motion after a rapid to its start.
double time_of(const std::string& setup, const std::string& motion) {
  const CheckReport before = check(setup + "\nM2\n");
  const CheckReport after = check(setup + "\n" + motion + "\nM2\n");
  EXPECT_TRUE(after.clean()) << after.str();
  return after.time.total - before.time.total;
}

TEST(Check, ACleanProgramIsClean) {
  const CheckReport r = check("G21 G90 G54\nT1 M6\nS1000 M3\nG0 X0 Y0 Z5\nG1 Z1 F100\nG2 X10 Y0 I5\nG0 Z20\nM2\n");
  EXPECT_TRUE(r.clean()) << r.str();
  EXPECT_EQ(r.lines, 8);
  EXPECT_EQ(r.motions, 4);
  EXPECT_EQ(r.rapids, 2);
  EXPECT_EQ(r.feeds, 1);
  EXPECT_EQ(r.arcs, 1);
  EXPECT_NE(r.str().find("c.ngc: clean"), std::string::npos) << r.str();
  EXPECT_NE(r.str().find("cycle time: "), std::string::npos);
}

TEST(Check, MovesOutsideTheEnvelopeAreFoundByLine) {
  // X-150 is machine X -50; Z-20 is machine Z -10.
  const CheckReport r = check("G0 X0 Y0 Z5\nG0 X-150\nG0 X0\nG1 Z-20 F100\nM2\n");
  ASSERT_EQ(r.envelope.size(), 2u) << r.str();
  EXPECT_EQ(r.envelope[0].line, 2);
  EXPECT_NE(r.envelope[0].message.find("X reaches -50, below the X travel [0, 400]"), std::string::npos)
      << r.envelope[0].message;
  EXPECT_EQ(r.envelope[1].line, 4);
  EXPECT_NE(r.envelope[1].message.find("Z reaches -10"), std::string::npos);
  EXPECT_FALSE(r.clean());
  EXPECT_NE(r.str().find("c.ngc:2: outside the envelope: X reaches -50"), std::string::npos) << r.str();
}

TEST(Check, AnArcBulgingOutOfTheEnvelopeIsFoundThoughItsEndsAreInside) {
  // Machine X of the end points: 10; the circle around machine X -10 reaches -30.
  const CheckReport bulge = check("G0 X-90 Y0 Z5\nG2 X-90 Y0 I-20 J0 F600\nM2\n");
  ASSERT_EQ(bulge.envelope.size(), 1u) << bulge.str();
  EXPECT_EQ(bulge.envelope[0].line, 2);
  EXPECT_NE(bulge.envelope[0].message.find("X reaches -30"), std::string::npos) << bulge.envelope[0].message;
  // Around machine X 10 from the top to the bottom of the circle: clockwise passes the
  // right side (X 30) and stays inside; counter-clockwise passes the left (X -10).
  const CheckReport right = check("G0 X-90 Y20 Z5\nG2 X-90 Y-20 I0 J-20 F600\nM2\n");
  EXPECT_TRUE(right.envelope.empty()) << right.str();
  const CheckReport left = check("G0 X-90 Y20 Z5\nG3 X-90 Y-20 I0 J-20 F600\nM2\n");
  ASSERT_EQ(left.envelope.size(), 1u) << left.str();
  EXPECT_NE(left.envelope[0].message.find("X reaches -10,"), std::string::npos) << left.envelope[0].message;
}

TEST(Check, RotaryPositionsOutsideTheirRangeOrOnMissingAxes) {
  const CheckReport r = check("G0 B120\nG0 A10\nM2\n");
  ASSERT_EQ(r.envelope.size(), 2u) << r.str();
  EXPECT_NE(r.envelope[0].message.find("B reaches 120 deg, outside the B range [-90, 90]"), std::string::npos);
  EXPECT_NE(r.envelope[1].message.find("the machine has no A axis"), std::string::npos);
}

TEST(Check, ToolNumbersTheMachineLacks) {
  const CheckReport r = check("T7 M6\nT100 M6\nT1 M6\nM2\n");
  ASSERT_EQ(r.tools.size(), 1u) << r.str();
  EXPECT_EQ(r.tools[0].line, 1);
  EXPECT_EQ(r.tools[0].column, 4);
  EXPECT_NE(r.tools[0].message.find("T7 is neither a cutting tool nor a head of machine 'test'; expected one of "
                                    "T1, T100 (ded)"),
            std::string::npos)
      << r.tools[0].message;
}

TEST(Check, DepositionWithoutAHeadAndTheSpindleWithAHead) {
  const CheckReport r = check("T1 M6\nM64 P0\nM65 P0\nT100 M6\nS1000 M3\nM5\nM2\n");
  ASSERT_EQ(r.process.size(), 2u) << r.str();
  EXPECT_EQ(r.process[0].line, 2);
  EXPECT_NE(r.process[0].message.find("deposition on for head 'ded' while T1"), std::string::npos);
  EXPECT_EQ(r.process[1].line, 5);
  EXPECT_NE(r.process[1].message.find("spindle started while T100 (head ded) is active"), std::string::npos);
}

TEST(Check, CuttingWithTheSpindleStoppedIsReportedOncePerRun) {
  const CheckReport r = check("T1 M6\nG0 X0 Y0 Z5\nG1 Z1 F100\nG1 X5\nS1000 M3\nG1 X6\nM5\nG1 X7\nM2\n");
  ASSERT_EQ(r.process.size(), 2u) << r.str();
  EXPECT_EQ(r.process[0].line, 3);
  EXPECT_EQ(r.process[1].line, 8);
}

TEST(Check, ErrorsAreCollectedAndCheckingGoesOn) {
  const CheckReport r = check("G0 X0 Y0 Z5\nG1 X10\nG0 X1 M104\nG0 X-150\nM2\n");
  ASSERT_EQ(r.errors.size(), 2u) << r.str();
  EXPECT_EQ(r.errors[0].line, 2);
  EXPECT_EQ(r.errors[0].column, 1);
  EXPECT_EQ(r.errors[1].line, 3);
  EXPECT_EQ(r.errors[1].column, 7);
  ASSERT_EQ(r.envelope.size(), 1u);  // line 4 was still checked
  EXPECT_EQ(r.envelope[0].line, 4);
  const std::string text = r.str();
  EXPECT_NE(text.find("c.ngc:2:1: error: found G1 with zero feed rate"), std::string::npos) << text;
  EXPECT_NE(text.find("c.ngc:3:7: error: found M104"), std::string::npos) << text;
  EXPECT_NE(text.find("c.ngc: 3 problems"), std::string::npos) << text;
}

TEST(Check, AProgramWithoutAnEndIsAnError) {
  const CheckReport r = check("G0 X0 Y0 Z5\n");
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_NE(r.errors[0].message.find("the program has no end"), std::string::npos);
}

TEST(CheckTime, AFeedMoveIsATrapezoid) {
  // 100 mm at 600 mm/min = 10 mm/s, X accelerates at 1000 mm/s²:
  // 10 s cruising plus 2 x (v/2a) = 0.01 s lost to accelerating and braking.
  EXPECT_NEAR(time_of("G0 X0 Y0 Z5", "G1 X100 F600"), 10.01, 1e-9);
}

TEST(CheckTime, RapidsRunAtTheAxesMaxFeedOrNeverReachIt) {
  // X: 200 mm/s, 1000 mm/s². 100 mm: 0.5 s + 0.2 s.
  EXPECT_NEAR(time_of("G0 X0 Y0 Z5", "G0 X100"), 0.7, 1e-9);
  // 1 mm never reaches 200 mm/s: a triangle, 2 sqrt(d / a).
  EXPECT_NEAR(time_of("G0 X0 Y0 Z5", "G0 X1"), 2 * std::sqrt(1.0 / 1000), 1e-9);
  // Z alone: 100 mm/s, 500 mm/s². 100 mm: 1 s + 0.2 s.
  EXPECT_NEAR(time_of("G0 X0 Y0 Z5", "G0 Z105"), 1.2, 1e-9);
  // X and Y together at 45 degrees: each axis at its limit, the path at sqrt(2) x 200 mm/s.
  const double d = 100 * std::sqrt(2.0), v = 200 * std::sqrt(2.0), a = 1000 * std::sqrt(2.0);
  EXPECT_NEAR(time_of("G0 X0 Y0 Z5", "G0 X100 Y100"), d / v + v / a, 1e-9);
}

TEST(CheckTime, AnArcIsItsLengthAtTheFeed) {
  // Full circle r = 10 at 600 mm/min: 20 pi mm at 10 mm/s (centripetal 10 mm/s² is far
  // below the limit), plus 0.01 s to accelerate and brake.
  EXPECT_NEAR(time_of("G0 X0 Y0 Z5", "G2 X0 Y0 I10 F600"), 2 * M_PI + 0.01, 1e-9);
  // Tiny radius at a high feed: capped by v = sqrt(a r) = sqrt(1000 x 0.1) = 10 mm/s.
  const double arc = 2 * M_PI * 0.1, v = 10, a = 1000;
  const double expected = arc * a >= v * v ? arc / v + v / a : 2 * std::sqrt(arc / a);
  EXPECT_NEAR(time_of("G0 X0 Y0 Z5", "G2 X0 Y0 I0.1 F6000"), expected, 1e-9);
}

TEST(CheckTime, DwellsCountAndProgramStopsAreTheOperators) {
  const CheckReport r = check("G4 P2.5\nM0\nM2\n");
  EXPECT_NEAR(r.time.total, 2.5, 1e-12);
  EXPECT_EQ(r.time.program_stops, 1);
  EXPECT_NE(r.time.str().find("1 program stop not timed"), std::string::npos) << r.time.str();
  EXPECT_EQ(format_duration(3725), "1 h 02 min 05 s");
  EXPECT_EQ(format_duration(75.25), "1 min 15.2 s");
  EXPECT_EQ(format_duration(4.04), "4.0 s");
}

/// The machine file's change times (its costs), as the planner's estimate counts them: a
/// tool change 8 s, a head switch 60 s more, a setup change 10 s, a refixture 15 min.
const Machine& machine_with_changes() {
  static const Machine m = parse_machine(
      std::string(kLinearAxes) +
      "heads:\n"
      "  - {name: ded, process: ded-powder, tool_number: 100, bead: {width: 1.5, height: 0.75}}\n"
      "tools:\n"
      "  - {number: 1, type: flat, diameter: 10}\n"
      "  - {number: 2, type: ball, diameter: 6}\n"
      "setups:\n"
      "  - {name: top, work_offset: G54, work_origin: [100, 50, 10]}\n"
      "  - {name: side, approach: +X, work_offset: G55, work_origin: [100, 50, 10]}\n"
      "  - {name: bottom, approach: -Z, work_offset: G56, work_origin: [100, 50, 10], manual_refixture: true}\n"
      "costs: {tool_change: 8, head_switch: 60, setup_change: 10, refixture: 15}\n",
      "changes.yaml");
  return m;
}

TEST(CheckTime, ChangesTakeTheMachineFilesTimes) {
  // The first tool loaded is a change; the same tool again is none; T2 -> T100 is a tool
  // change and a head switch; G54 -> G55 a setup change; G55 -> G56 (re-clamped) and back
  // to G54 two refixtures.
  const std::string program = "G54\nT1 M6\nT1 M6\nT2 M6\nT100 M6\nG55\nM0\nG56\nG54\nM2\n";
  const CheckReport r = check_program(program, machine_with_changes(), "c.ngc");
  ASSERT_TRUE(r.clean()) << r.str();
  EXPECT_EQ(r.time.tool_changes, 3);
  EXPECT_EQ(r.time.head_switches, 1);
  EXPECT_EQ(r.time.setup_changes, 1);
  EXPECT_EQ(r.time.refixtures, 2);
  EXPECT_NEAR(r.time.total, 3 * 8 + 60 + 10 + 2 * 15 * 60, 1e-9);
  EXPECT_NEAR(r.time.motion, 0, 1e-12);
  EXPECT_NE(r.time.str().find("3 tool changes 24.0 s, 1 head switch 1 min 00.0 s, 1 setup change 10.0 s, 2 "
                              "refixtures 30 min 00.0 s"),
            std::string::npos)
      << r.time.str();
}

TEST(CheckTime, TheCycleTimeIsMotionDwellAndChanges) {
  const CheckReport r = check_program("G54\nT1 M6\nS1000 M3\nG0 X0 Y0 Z5\nG1 X100 F6000\nG4 P1\nM2\n",
                                      machine_with_changes(), "c.ngc");
  ASSERT_TRUE(r.clean()) << r.str();
  EXPECT_NEAR(r.time.motion, r.time.feed + r.time.rapid, 1e-12);
  EXPECT_NEAR(r.time.total, r.time.motion + 1.0 + 8.0, 1e-9);
  EXPECT_EQ(r.time.str().rfind(format_duration(r.time.total) + ": motion ", 0), 0u) << r.time.str();
}

TEST(CheckTime, RotaryMovesUseTheRotaryLimits) {
  // B: 3600 deg/min = 60 deg/s, 360 deg/s². 90 deg: 1.5 s + 60/360 s.
  EXPECT_NEAR(time_of("G0 X0 Y0 Z5", "G0 B90"), 1.5 + 60.0 / 360.0, 1e-9);
}

}  // namespace
