// The machine-file keys the G-code module reads: setups[].work_origin (where a setup's
// work zero sits on the machine) and heads[].tool_number (the T number that selects a
// head). Defaults, values as written, and mistakes reported at their place.

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "config/machine_loader.hpp"

namespace {

using hybridctl::config::Diagnostic;
using hybridctl::config::Machine;
using hybridctl::config::MachineFileError;
using hybridctl::config::parse_machine;

// Line numbers on the right.
const std::string kBase =
    "name: test\n"                                                     //  1
    "envelope:\n"                                                      //  2
    "  X: {travel: [0, 400]}\n"                                        //  3
    "  Y: {travel: [-100, 300]}\n"                                     //  4
    "  Z: {travel: [20, 300]}\n"                                       //  5
    "heads:\n"                                                         //  6
    "  - {name: ded, process: ded-powder, bead: {width: 2, height: 1}}\n"  //  7
    "  - {name: arc, process: wire-arc, bead: {width: 6, height: 2}}\n"    //  8
    "tools:\n"                                                         //  9
    "  - {number: 1, type: flat, diameter: 10}\n"                      // 10
    "setups:\n"                                                        // 11
    "  - name: top\n";                                                 // 12

std::vector<Diagnostic> problems(const std::string& yaml) {
  try {
    parse_machine(yaml, "m.yaml");
  } catch (const MachineFileError& e) {
    return e.diagnostics();
  }
  ADD_FAILURE() << "expected a MachineFileError for:\n" << yaml;
  return {};
}

void expect_one(const std::string& yaml, const std::string& prefix, const std::vector<std::string>& words) {
  const auto ds = problems(yaml);
  ASSERT_EQ(ds.size(), 1u);
  const std::string text = ds[0].str();
  EXPECT_EQ(text.rfind(prefix, 0), 0u) << "expected prefix '" << prefix << "' in: " << text;
  for (const auto& w : words) EXPECT_NE(text.find(w), std::string::npos) << "'" << w << "' missing in: " << text;
}

TEST(WorkOrigin, DefaultsToTheMiddleOfXAndYAndTheBottomOfZ) {
  const Machine m = parse_machine(kBase, "m.yaml");
  const std::array<double, 3> expected = {200.0, 100.0, 20.0};
  EXPECT_EQ(m.setups.at(0).work_origin, expected);
}

TEST(WorkOrigin, IsReadAsMachineCoordinates) {
  const Machine m = parse_machine(kBase + "    work_origin: [150, -20.5, 80]\n", "m.yaml");
  const std::array<double, 3> expected = {150.0, -20.5, 80.0};
  EXPECT_EQ(m.setups.at(0).work_origin, expected);
}

TEST(WorkOrigin, MustBeThreeNumbers) {
  expect_one(kBase + "    work_origin: [1, 2]\n", "m.yaml:13:18: setups[0].work_origin: ",
             {"expected the machine coordinates of the work zero as [x, y, z] in mm, got a list of 2"});
  expect_one(kBase + "    work_origin: [1, two, 3]\n", "m.yaml:13:22: setups[0].work_origin[1]: ",
             {"expected a number in mm, got 'two'"});
}

TEST(WorkOrigin, SetupsSharingAWorkOffsetMustShareTheOrigin) {
  EXPECT_NO_THROW(parse_machine(kBase + "  - name: again\n", "m.yaml"));  // both G54 at the default
  expect_one(kBase + "  - name: flipped\n    work_offset: G54\n    work_origin: [10, 10, 30]\n",
             "m.yaml:14:18: setups[1].work_offset: ",
             {"G54 is already the work offset of setup 'top' with another work_origin"});
}

TEST(HeadToolNumber, DefaultsTo100PlusTheHeadIndex) {
  const Machine m = parse_machine(kBase, "m.yaml");
  EXPECT_EQ(m.heads.at(0).tool_number, 100);
  EXPECT_EQ(m.heads.at(1).tool_number, 101);
  EXPECT_EQ(m.find_head_by_tool(101)->name, "arc");
  EXPECT_EQ(m.find_head_by_tool(1), nullptr);
}

TEST(HeadToolNumber, IsReadAsWritten) {
  std::string yaml = kBase;
  yaml.replace(yaml.find("bead: {width: 2"), 4, "tool_number: 50, bead");
  const Machine m = parse_machine(yaml, "m.yaml");
  EXPECT_EQ(m.heads.at(0).tool_number, 50);
  EXPECT_EQ(m.heads.at(1).tool_number, 101);
}

TEST(HeadToolNumber, MayNotBeACuttingToolNumber) {
  std::string yaml = kBase;
  yaml.replace(yaml.find("bead: {width: 6"), 4, "tool_number: 1, bead");
  expect_one(yaml, "m.yaml:8:49: heads[1].tool_number: ",
             {"tool number 1 is already the number of the cutting tool at line 10"});
}

TEST(HeadToolNumber, ADefaultThatClashesSaysWhichKeyToSet) {
  std::string yaml = kBase;
  yaml.replace(yaml.find("number: 1,"), 10, "number: 101,");
  expect_one(yaml, "m.yaml:8:5: heads[1].tool_number: ",
             {"the default tool number 101", "cutting tool at line 10", "set heads[1].tool_number"});
}

TEST(HeadToolNumber, MayNotRepeatAnotherHeads) {
  std::string yaml = kBase;
  yaml.replace(yaml.find("bead: {width: 6"), 4, "tool_number: 100, bead");
  expect_one(yaml, "m.yaml:8:49: heads[1].tool_number: ", {"already the tool number of head 'ded'"});
  std::string bad = kBase;
  bad.replace(bad.find("bead: {width: 6"), 4, "tool_number: 0, bead");
  expect_one(bad, "m.yaml:8:49: heads[1].tool_number: ", {"expected a positive integer tool number"});
}

}  // namespace

namespace {

// A problem found after loading (a code the dialect's controller does not run) is placed at
// its key: the value's line and column; for a key the file leaves to its default, the
// deepest key of the path the file writes; for a path the file has none of, the file.
TEST(MachineKeyPlaces, AKeyPathIsPlacedAtItsValueOrItsDeepestWrittenParent) {
  using hybridctl::config::diagnostic_at;
  const std::string yaml = kBase + "gcode:\n  m_codes:\n    spindle_cw: M203\n";  // lines 13-15
  const Diagnostic value = diagnostic_at(yaml, "m.yaml", "gcode.m_codes.spindle_cw", "what");
  EXPECT_EQ(value.str(), "m.yaml:15:17: what");
  const Diagnostic defaulted = diagnostic_at(yaml, "m.yaml", "gcode.m_codes.spindle_ccw", "what");
  EXPECT_EQ(defaulted.line, 14) << "the m_codes mapping, which leaves spindle_ccw to its default";
  const Diagnostic head = diagnostic_at(yaml, "m.yaml", "heads[1].bead", "what");
  EXPECT_EQ(head.line, 8);
  EXPECT_EQ(diagnostic_at(yaml, "m.yaml", "heads[7].codes.on", "what").line, 6) << "no 8th head: the heads sequence";
  EXPECT_EQ(diagnostic_at(yaml, "m.yaml", "coolant.pressure", "what").str(), "m.yaml: what");
}

}  // namespace
