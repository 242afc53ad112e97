// Every kind of problem in a machine file gets a diagnostic at its exact place
// ("file:line:column: path: what is wrong, what was expected"), all problems of a file
// come back in one pass in file order, and no input makes the loader throw anything but
// MachineFileError.

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "config/machine_loader.hpp"

namespace {

using hybridctl::config::Diagnostic;
using hybridctl::config::Machine;
using hybridctl::config::MachineFileError;
using hybridctl::config::parse_machine;

// A valid machine; the tests below change one thing in it. Line numbers on the right.
const std::string kBase =
    "name: test\n"                   //  1
    "envelope:\n"                    //  2
    "  X: {travel: [0, 400]}\n"      //  3
    "  Y: {travel: [0, 300]}\n"      //  4
    "  Z: {travel: [0, 300]}\n"      //  5
    "tools:\n"                       //  6
    "  - number: 1\n"                //  7
    "    type: flat\n"               //  8
    "    diameter: 10\n"             //  9
    "setups:\n"                      // 10
    "  - name: top\n";               // 11

/// kBase with the first occurrence of `from` replaced by `to`.
std::string with(const std::string& from, const std::string& to, std::string text = kBase) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "test bug: '" << from << "' not in the document";
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

/// The diagnostics of a document that must fail to load.
std::vector<Diagnostic> problems(const std::string& yaml) {
  try {
    parse_machine(yaml, "m.yaml");
  } catch (const MachineFileError& e) {
    return e.diagnostics();
  }
  ADD_FAILURE() << "expected a MachineFileError for:\n" << yaml;
  return {};
}

std::string all(const std::vector<Diagnostic>& ds) {
  std::string out;
  for (const auto& d : ds) out += d.str() + "\n";
  return out;
}

/// Exactly one diagnostic, starting with `prefix` and containing every word in `words`.
void expect_one(const std::string& yaml, const std::string& prefix, const std::vector<std::string>& words) {
  const auto ds = problems(yaml);
  ASSERT_EQ(ds.size(), 1u) << all(ds);
  const std::string text = ds[0].str();
  EXPECT_EQ(text.rfind(prefix, 0), 0u) << "expected prefix '" << prefix << "' in: " << text;
  for (const auto& w : words) EXPECT_NE(text.find(w), std::string::npos) << "'" << w << "' missing in: " << text;
}

TEST(MachineErrors, TheBaseDocumentIsValid) {
  const Machine m = parse_machine(kBase, "m.yaml");
  EXPECT_EQ(m.name, "test");
  ASSERT_EQ(m.tools.size(), 1u);
  EXPECT_EQ(m.tools[0].diameter, 10.0);
}

TEST(MachineErrors, UnknownKeyNamesTheExpectedKeysAndSuggestsTheClosest) {
  expect_one(with("    diameter: 10\n", "    diameter: 10\n    step_ovr: 2\n"), "m.yaml:10:5: tools[0]: ",
             {"unknown key 'step_ovr'", "did you mean 'step_over'?", "expected one of number, name, type, diameter"});
}

TEST(MachineErrors, UnknownKeyFarFromEveryKeyHasNoSuggestion) {
  const auto ds = problems(with("name: test\n", "name: test\ncolour: red\n"));
  ASSERT_EQ(ds.size(), 1u) << all(ds);
  EXPECT_EQ(ds[0].str().rfind("m.yaml:2:1: unknown key 'colour'; expected one of name, description, envelope", 0), 0u)
      << ds[0].str();
  EXPECT_EQ(ds[0].str().find("did you mean"), std::string::npos) << ds[0].str();
}

TEST(MachineErrors, WrongTypeSaysWhatWasExpectedAndWhatWasGiven) {
  expect_one(with("diameter: 10", "diameter: ten"), "m.yaml:9:15: tools[0].diameter: ",
             {"expected a number in mm, got 'ten'"});
  expect_one(with("diameter: 10", "diameter: \"10\""), "m.yaml:9:15: tools[0].diameter: ",
             {"expected a number in mm, got the quoted string '10'"});
  expect_one(with("  X: {travel: [0, 400]}", "  X: {travel: 400}"), "m.yaml:3:15: envelope.X.travel: ",
             {"expected [min, max] in mm, got 400"});
}

TEST(MachineErrors, MissingFieldPointsAtTheParentMappingAndNamesTheField) {
  expect_one(with("    type: flat\n", ""), "m.yaml:7:5: tools[0]: ", {"missing required field 'type'"});
  expect_one(with("name: test\n", ""), "m.yaml:1:1: ", {"missing required field 'name'"});
  expect_one(with("  Y: {travel: [0, 300]}\n", ""), "m.yaml:3:3: envelope: ", {"missing required field 'Y'"});
}

TEST(MachineErrors, NonPositiveSizeIsRejected) {
  expect_one(with("diameter: 10", "diameter: -3"), "m.yaml:9:15: tools[0].diameter: ",
             {"expected a positive length in mm, got -3"});
  expect_one(with("diameter: 10", "diameter: 0"), "m.yaml:9:15: tools[0].diameter: ",
             {"expected a positive length in mm, got 0"});
}

TEST(MachineErrors, OutOfRangeValuesAreRejected) {
  // step_over may not exceed the diameter; a ball's corner radius is diameter/2.
  expect_one(with("    diameter: 10\n", "    diameter: 10\n    step_over: 12\n"), "m.yaml:10:16: tools[0].step_over: ",
             {"expected at most the tool diameter 10 mm, got 12"});
  expect_one(with("    type: flat\n    diameter: 10\n", "    type: ball\n    diameter: 10\n    corner_radius: 4\n"),
             "m.yaml:10:20: tools[0].corner_radius: ", {"expected diameter/2 = 5 mm for a ball end mill, got 4"});
  expect_one(with("  X: {travel: [0, 400]}", "  X: {travel: [400, 0]}"), "m.yaml:3:15: envelope.X.travel: ",
             {"with min < max, got [400, 0]"});
}

TEST(MachineErrors, DuplicateToolNumberPointsAtTheSecondAndNamesTheLineOfTheFirst) {
  expect_one(with("setups:\n", "  - number: 1\n    type: ball\n    diameter: 6\nsetups:\n"),
             "m.yaml:10:13: tools[1].number: ", {"duplicate tool number 1, first used at line 7"});
}

TEST(MachineErrors, DuplicateSetupNameIsReported) {
  expect_one(kBase + "  - name: top\n", "m.yaml:12:11: setups[1].name: ",
             {"duplicate setup name 'top', first used at line 11"});
}

TEST(MachineErrors, ToolLongerThanTheZTravelIsReportedAtTheTool) {
  // Default flute 3 x 10 = 30 and shank 2 x 10 = 20, plus the 400 mm holder.
  expect_one(with("    diameter: 10\n", "    diameter: 10\n    holder: {diameter: 40, length: 400}\n"),
             "m.yaml:7:5: tools[0] (T1): ",
             {"stick-out 450 mm", "flute 30 + shank 20 + holder 400", "exceeds the Z travel of 300 mm"});
}

TEST(MachineErrors, BadEnumValueListsTheExpectedValues) {
  expect_one(with("type: flat", "type: flta"), "m.yaml:8:11: tools[0].type: ",
             {"expected one of flat, ball, bull, got 'flta'", "did you mean 'flat'?"});
  expect_one(with("tools:\n", "heads:\n  - {name: h, process: plasma, bead: {width: 2, height: 1}}\ntools:\n"),
             "m.yaml:7:24: heads[0].process: ",
             {"expected one of ded-powder, ded-wire, wire-arc, laser-wire, got 'plasma'"});
}

TEST(MachineErrors, BadUriIsReportedAtTheUriWithTheExpectedForms) {
  expect_one(kBase + "transports:\n  sim: modbus-tcp://localhost\n", "m.yaml:13:8: transports.sim: ",
             {"bad transport URI 'modbus-tcp://localhost'", "missing ':PORT'", "modbus-tcp://HOST:PORT[?unit=N]"});
  expect_one(kBase + "transports:\n  sim: http://localhost:80\n", "m.yaml:13:8: transports.sim: ",
             {"unknown scheme 'http'", "modbus-tcp://HOST:PORT", "modbus-rtu:///dev/DEVICE", "socketcan://IFACE",
              "socketcand://HOST:PORT/CHANNEL"});
}

TEST(MachineErrors, BadWorkOffsetListsG54ToG59) {
  expect_one(kBase + "    work_offset: G60\n", "m.yaml:12:18: setups[0].work_offset: ",
             {"expected one of G54, G55, G56, G57, G58, G59, got 'G60'"});
}

TEST(MachineErrors, RotaryPositionOutsideTheAxisRange) {
  const std::string with_b = with("  Z: {travel: [0, 300]}\n", "  Z: {travel: [0, 300]}\n  B: {range: [-120, 120]}\n");
  expect_one(with_b + "    rotary: {B: 135}\n", "m.yaml:13:17: setups[0].rotary.B: ",
             {"expected an angle within the B axis range [-120, 120] degrees, got 135"});
  EXPECT_NO_THROW(parse_machine(with_b + "    rotary: {B: -120}\n", "m.yaml"));
}

TEST(MachineErrors, RotaryPositionForAnAxisTheMachineLacks) {
  expect_one(kBase + "    rotary: {A: 10}\n", "m.yaml:12:14: setups[0].rotary.A: ",
             {"the machine has no A axis", "it has no rotary axes"});
}

TEST(MachineErrors, UnknownMCodeNameAndBadMCode) {
  expect_one(kBase + "gcode:\n  m_codes: {spindle_cv: M3}\n", "m.yaml:13:13: gcode.m_codes: ",
             {"unknown key 'spindle_cv'", "did you mean 'spindle_cw'?"});
  expect_one(kBase + "gcode:\n  m_codes: {program_end: X30}\n", "m.yaml:13:26: gcode.m_codes.program_end: ",
             {"expected an M code such as M30, got 'X30'"});
}

TEST(MachineErrors, LayerHeightAboveTheBeadHeight) {
  expect_one(with("tools:\n", "heads:\n  - {name: h, process: wire-arc, bead: {width: 6, height: 2}, layer_height: 2.5}\ntools:\n"),
             "m.yaml:7:77: heads[0].layer_height: ", {"expected at most the bead height 2 mm, got 2.5"});
}

TEST(MachineErrors, DuplicateKeyIsReportedAtTheSecond) {
  expect_one(with("    diameter: 10\n", "    diameter: 10\n    diameter: 12\n"), "m.yaml:10:5: tools[0].diameter: ",
             {"duplicate key, first given at line 9"});
}

TEST(MachineErrors, NoHeadOrToolAndNoSetup) {
  const auto ds = problems("name: x\nenvelope:\n  X: {travel: [0, 1]}\n  Y: {travel: [0, 1]}\n  Z: {travel: [0, 1]}\n");
  ASSERT_EQ(ds.size(), 2u) << all(ds);
  EXPECT_EQ(ds[0].str().rfind("m.yaml:1:1: missing required field 'heads' or 'tools'", 0), 0u) << all(ds);
  EXPECT_EQ(ds[1].str().rfind("m.yaml:1:1: missing required field 'setups'", 0), 0u) << all(ds);
}

TEST(MachineErrors, YamlSyntaxErrorIsOneDiagnosticAtItsPlace) {
  expect_one(with("type: flat", "type: flat: round"), "m.yaml:8:15: ", {"YAML syntax error", "illegal map value"});
}

TEST(MachineErrors, EmptyFileAndCommentOnlyFile) {
  expect_one("", "m.yaml:1:1: ", {"empty machine file", "expected a mapping"});
  expect_one("# nothing but a comment\n\n", "m.yaml:1:1: ", {"empty machine file"});
}

TEST(MachineErrors, AStrayCommaIsASyntaxErrorNotAnEndlessLoop) {
  // Found by fuzz/machine_fuzz (fuzz/corpus/machine/regression-stray-comma.yaml): yaml-cpp
  // 0.7's LoadAll looped forever, allocating, on a document starting with ','.
  expect_one(",", "m.yaml:1:1: ", {"YAML syntax error: found ',', which starts no value", "expected a mapping"});
  expect_one("# machine\n  , name: x\n", "m.yaml:2:3: ", {"YAML syntax error: found ','"});
  expect_one(kBase + "---\n,\n", "m.yaml:12:1: ", {"one YAML document; expected no second document here"});
}

TEST(MachineErrors, ASecondDocumentIsReportedWhereItStarts) {
  const auto ds = problems(kBase + "---\nname: other\n");
  ASSERT_EQ(ds.size(), 1u) << all(ds);
  EXPECT_EQ(ds[0].str(), "m.yaml:12:1: a machine file holds one YAML document; expected no second document here");
}

TEST(MachineErrors, DocumentThatIsNotAMapping) {
  expect_one("just a scalar\n", "m.yaml:1:1: ", {"expected a mapping", "got 'just a scalar'"});
  expect_one("- a\n- b\n", "m.yaml:1:1: ", {"expected a mapping", "got a list"});
}

TEST(MachineErrors, UnreadablePathIsOneDiagnosticWithoutAPlace) {
  try {
    hybridctl::config::load_machine("/nonexistent/dir/machine.yaml");
    FAIL() << "expected a MachineFileError";
  } catch (const MachineFileError& e) {
    ASSERT_EQ(e.diagnostics().size(), 1u);
    EXPECT_EQ(e.diagnostics()[0].line, 0);
    EXPECT_EQ(e.diagnostics()[0].str(), "/nonexistent/dir/machine.yaml: cannot read: No such file or directory");
  }
  try {
    hybridctl::config::load_machine(std::filesystem::temp_directory_path());
    FAIL() << "expected a MachineFileError";
  } catch (const MachineFileError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot read: Is a directory"), std::string::npos) << e.what();
  }
}

TEST(MachineErrors, LoadMachineReportsTheFileNameAsGiven) {
  const auto path = std::filesystem::temp_directory_path() / ("hybridctl-config-" + std::to_string(::getpid()) + ".yaml");
  std::ofstream(path) << with("diameter: 10", "diameter: -1");
  try {
    hybridctl::config::load_machine(path);
    ADD_FAILURE() << "expected a MachineFileError";
  } catch (const MachineFileError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(path.string() + ":9:15: tools[0].diameter:", 0), 0u) << e.what();
  }
  std::filesystem::remove(path);
}

TEST(MachineErrors, EveryProblemIsReportedInOnePassInFileOrder) {
  const std::string yaml =
      "name: multi\n"                                   //  1
      "envelope:\n"                                     //  2
      "  X: {travel: [0, 400], max_feed: fast}\n"       //  3  wrong type
      "  Y: {travel: [0, 300]}\n"                       //  4
      "  Z: {travel: [0, 300]}\n"                       //  5
      "tools:\n"                                        //  6
      "  - {number: 1, type: flat, diameter: 10}\n"     //  7
      "  - {number: 1, type: ball, diameter: -6}\n"     //  8  duplicate number, negative diameter
      "setups:\n"                                       //  9
      "  - {name: top, approach: up}\n"                 // 10  bad enum
      "  - {name: top, work_offset: G54}\n"             // 11  duplicate name
      "planning: {voxl_size: 1, top_k: 0}\n"            // 12  unknown key, out of range
      "transports: {x: 'socketcan://'}\n";              // 13  bad URI
  const auto ds = problems(yaml);
  const std::vector<std::string> expected_prefixes = {
      "m.yaml:3:35: envelope.X.max_feed: expected a number in mm/min, got 'fast'",
      "m.yaml:8:14: tools[1].number: duplicate tool number 1, first used at line 7",
      "m.yaml:8:39: tools[1].diameter: expected a positive length in mm, got -6",
      "m.yaml:10:27: setups[0].approach: expected one of +X, -X, +Y, -Y, +Z, -Z, got 'up'",  // no suggestion
      "m.yaml:11:12: setups[1].name: duplicate setup name 'top', first used at line 10",
      "m.yaml:12:12: planning: unknown key 'voxl_size' (did you mean 'voxel_size'?)",
      "m.yaml:12:33: planning.top_k: expected an integer number of plans from 1 to 1000, got 0",
      "m.yaml:13:17: transports.x: bad transport URI 'socketcan://'",
  };
  ASSERT_EQ(ds.size(), expected_prefixes.size()) << all(ds);
  for (std::size_t i = 0; i < ds.size(); ++i)
    EXPECT_EQ(ds[i].str().rfind(expected_prefixes[i], 0), 0u) << "#" << i << ": " << ds[i].str();
  EXPECT_EQ(ds[3].str().find("did you mean"), std::string::npos) << "'up' is nothing like '+X': " << ds[3].str();
}

TEST(MachineErrors, WhatListsEveryDiagnosticOnePerLineAndIsAnInputError) {
  const std::string yaml = with("diameter: 10", "diameter: -1", with("type: flat", "type: round"));
  try {
    parse_machine(yaml, "m.yaml");
    FAIL() << "expected a MachineFileError";
  } catch (const hybridctl::InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "m.yaml:8:11: tools[0].type: expected one of flat, ball, bull, got 'round'\n"
              "m.yaml:9:15: tools[0].diameter: expected a positive length in mm, got -1");
  }
}

TEST(MachineErrors, FloodsOfProblemsAreCappedWithACount) {
  std::string yaml = kBase + "planning:\n";
  for (int i = 0; i < 300; ++i) yaml += "  bogus" + std::to_string(i) + ": 1\n";
  const auto ds = problems(yaml);
  ASSERT_EQ(ds.size(), 101u);
  EXPECT_NE(ds.back().message.find("200 more problems not shown"), std::string::npos) << ds.back().str();
}

// ---------------------------------------------------------------- garbage never crashes

/// Parsing either succeeds or throws MachineFileError with at least one diagnostic.
::testing::AssertionResult only_machine_file_errors(const std::string& text) {
  try {
    parse_machine(text, "g.yaml");
  } catch (const MachineFileError& e) {
    if (e.diagnostics().empty()) return ::testing::AssertionFailure() << "MachineFileError without diagnostics";
  } catch (const std::exception& e) {
    return ::testing::AssertionFailure() << "other exception: " << e.what();
  } catch (...) {
    return ::testing::AssertionFailure() << "non-standard exception";
  }
  return ::testing::AssertionSuccess();
}

TEST(MachineGarbage, HostileDocumentsOnlyEverThrowMachineFileError) {
  std::string binary(4096, '\0');
  std::mt19937 random(42);
  for (auto& c : binary) c = static_cast<char>(random());
  const std::vector<std::string> inputs = {
      "",
      "~",
      "42",
      "[1, 2, 3]",
      "---\n---\n",
      "name: a\n---\nname: b\n",
      binary,
      std::string(10000, '[') + std::string(10000, ']'),
      std::string(5000, '{'),
      "a: &x [*x]",
      "tools: &t [*t, *t]\nname: x",
      "name: [1, {2: 3}]\nenvelope: {X: {travel: [.nan, .inf]}, Y: {travel: [1e999, -1e999]}, Z: []}\n",
      "tools: [{number: 99999999999999999999999, diameter: 1e400, type: !!binary aGVsbG8=}]\n",
      "? [a, b]\n: 1\n{x: 1}: 2\n",
      "setups: [{rotary: {B: 1, A: [1], Q: {}}}]\nenvelope: {B: {range: [5, 5]}}\n",
      "transports: {a: 'modbus-rtu:///dev/x?baud=&parity=', b: 'socketcand://[::1:5/c', c: '\\x01'}\n",
      "heads: [{bead: [], nozzle: 3, codes: {power: 'no placeholder'}, primitives: []}]\n",
      "\xef\xbb\xbfname: bom\n",
      "name: \"\\u0000\\x07\"\n",
  };
  for (const auto& input : inputs) EXPECT_TRUE(only_machine_file_errors(input)) << input.substr(0, 200);
}

TEST(MachineGarbage, EveryTruncationAndRandomMutationOfAnExampleIsSafe) {
  std::ifstream in(std::string(HYBRIDCTL_SOURCE_DIR) + "/examples/machines/multitask-b-axis.yaml");
  std::stringstream buffer;
  buffer << in.rdbuf();
  const std::string example = buffer.str();
  ASSERT_GT(example.size(), 1000u);
  for (std::size_t n = 0; n < example.size(); n += 7) ASSERT_TRUE(only_machine_file_errors(example.substr(0, n))) << n;
  std::mt19937 random(7);
  const std::string alphabet = "{}[]:-,'\"&*!|>#?% \n\t0123456789abcXYZ.";
  for (int round = 0; round < 300; ++round) {
    std::string mutated = example;
    for (int k = 0; k < 5; ++k) mutated[random() % mutated.size()] = alphabet[random() % alphabet.size()];
    ASSERT_TRUE(only_machine_file_errors(mutated)) << mutated;
  }
}

}  // namespace
