// hybridctl export as a user runs it: the flanged hub's hybrid plan exported, its programs
// accepted by LinuxCNC's own interpreter (rs274, the real peer unpacked by scripts/setup);
// a plan that leaves the envelope and bad requests write nothing. (Every program of the
// example parts' best plans through rs274 and `gcode check`: whole_plan_test.cpp.)

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include "shell.hpp"

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

namespace {

namespace fs = std::filesystem;

const fs::path kSource = HYBRIDCTL_SOURCE_DIR;

// Outcome, quote, slurp, run_shell, DirectoryTest.
using namespace hybridctl::cli_testing;

class Export : public DirectoryTest {
 protected:
  Export() : DirectoryTest("export") {}
  Outcome sh(const std::string& command) { return run_shell(command, dir_); }
  Outcome hybridctl(const std::vector<std::string>& args) { return run_hybridctl(args); }

};

// The hybrid plan a shop would run by hand for the flanged hub: turned over, deposit the
// hub with the flange on the plate with its machining allowance, then mill it to size from
// the same side. Export executes it from the raw stock and judges it against the STL (the
// search alone ranks it, 14th by the estimate), and its program deposits (the head's
// output, M64/M65 P0) and mills (the spindle, M3), which LinuxCNC's rs274 accepts.
TEST_F(Export, TheFlangedHubDepositedThenMilledIsAValidatedPlanThatExports) {
  const std::string machine = (kSource / "examples/machines/hybrid-3axis.yaml").string();
  const fs::path plan = dir_ / "plan";
  const Outcome planned = hybridctl({"plan", (kSource / "examples/parts/flanged-hub.stl").string(), "--machine", machine,
                                     "--voxel", "0.5", "--tolerance", "1.0", "--top", "16", "--no-validate", "-o",
                                     plan.string()});
  ASSERT_EQ(planned.exit_code, 0) << planned.out << planned.err;
  const std::size_t at = planned.out.find(". (P6 \u2212 P9)  cost");
  ASSERT_NE(at, std::string::npos) << planned.out;
  const std::size_t line = planned.out.rfind('\n', at) + 1;
  const std::string rank = planned.out.substr(line, at - line);
  EXPECT_NE(planned.out.find("P6   O-AM ded from -Z (bottom)"), std::string::npos) << planned.out;
  EXPECT_NE(planned.out.find("P9   SM-max T1 (10 mm flat rougher) from -Z (bottom)"), std::string::npos) << planned.out;

  const fs::path out = dir_ / "out";
  const Outcome exported = hybridctl({"export", plan.string(), "--plan", rank.substr(rank.find_first_not_of(' ')), "-o", out.string()});
  ASSERT_EQ(exported.exit_code, 0) << exported.out << exported.err;
  EXPECT_TRUE(std::regex_search(exported.out, std::regex("\nexact       [^\n]*: within tolerance\n"))) << exported.out;
  const std::string name = "plan-" + rank.substr(rank.find_first_not_of(' ')) + ".ngc";
  const std::string program = slurp(out / name);
  EXPECT_NE(program.find("M64 P0"), std::string::npos);
  EXPECT_NE(program.find("M65 P0"), std::string::npos);
  EXPECT_NE(program.find("S8000 M3"), std::string::npos) << "T1 at its spindle speed";
  const Outcome linuxcnc = sh(quote((kSource / "scripts/rs274").string()) + " -t " + quote((out / "tool.tbl").string()) + " -g " +
                              quote((out / name).string()));
  EXPECT_EQ(linuxcnc.exit_code, 0) << linuxcnc.err.substr(0, 2000);
}

// A plan planned for a machine whose X travel is too short for the part where its setup
// holds it: export posts the program, finds the first move beyond the travel and writes
// nothing (exit 3, the action, the line and the axis). The bracket, which export refused
// here before, has no plan at all now: `plan` proves that no order of the primitives makes
// it (Cli.TheBracketIsProvenNotManufacturable...).
TEST_F(Export, APlanThatLeavesTheMachineEnvelopeIsRefusedAndNothingIsWritten) {
  std::string yaml = slurp(kSource / "examples/machines/hybrid-3axis.yaml");
  const std::string travel = "X: {travel: [0, 400]";
  ASSERT_NE(yaml.find(travel), std::string::npos);
  yaml.replace(yaml.find(travel), travel.size(), "X: {travel: [0, 235]");  // the hub reaches X 250 from work origin 200
  const fs::path machine = dir_ / "short-x.yaml";
  std::ofstream(machine) << yaml;
  const fs::path plan = dir_ / "plan";
  const Outcome planned = hybridctl({"plan", "--no-validate", (kSource / "examples/parts/flanged-hub.stl").string(), "--machine",
                                     machine.string(), "--voxel", "0.5", "--top", "1", "-o", plan.string()});
  ASSERT_EQ(planned.exit_code, 0) << planned.out << planned.err;
  const Outcome exported = hybridctl({"export", plan.string(), "--plan", "1", "-o", (dir_ / "out").string()});
  EXPECT_EQ(exported.exit_code, 3) << exported.out << exported.err;
  EXPECT_FALSE(fs::exists(dir_ / "out")) << "export wrote a refused plan";
  EXPECT_NE(exported.err.find("beyond the X travel [0, 235]; nothing was written"), std::string::npos) << exported.err;
}

TEST_F(Export, AFanucProgramHasItsMarksAndParsesBack) {
  const std::string machine = (kSource / "examples/machines/hybrid-3axis.yaml").string();
  const fs::path plan = dir_ / "plan";
  ASSERT_EQ(hybridctl({"plan", "--no-validate", (kSource / "examples/parts/overhang.stl").string(), "--machine", machine, "--voxel", "0.5",
                       "--top", "1", "-o", plan.string()})
                .exit_code,
            0);
  const Outcome exported = hybridctl({"export", plan.string(), "--dialect", "fanuc", "-o", (dir_ / "out").string()});
  ASSERT_EQ(exported.exit_code, 0) << exported.err;
  const std::string text = slurp(dir_ / "out" / "plan-1.nc");
  EXPECT_EQ(text.rfind("%\n", 0), 0u);
  EXPECT_NE(text.find("\nO"), std::string::npos);
  EXPECT_NE(text.find("\nN10 "), std::string::npos);
  EXPECT_EQ(text.substr(text.size() - 2), "%\n");
}

TEST_F(Export, BadRequestsSayWhatWasExpectedAndWriteNothing) {
  const Outcome missing = hybridctl({"export", (dir_ / "nothing").string(), "-o", (dir_ / "out").string()});
  EXPECT_EQ(missing.exit_code, 3);
  EXPECT_NE(missing.err.find("plan.json"), std::string::npos) << missing.err;
  EXPECT_FALSE(fs::exists(dir_ / "out"));

  std::ofstream(dir_ / "plan.json") << R"({"format": "hybridctl-plan", "version": 7})";
  const Outcome version = hybridctl({"export", (dir_ / "plan.json").string(), "-o", (dir_ / "out").string()});
  EXPECT_EQ(version.exit_code, 3);
  EXPECT_NE(version.err.find("/version: expected version 1"), std::string::npos) << version.err;

  std::ofstream(dir_ / "plan.json") << R"({"format": "hybridctl-plan", "version": 1, "part": 3})";
  const Outcome typed = hybridctl({"export", (dir_ / "plan.json").string(), "-o", (dir_ / "out").string()});
  EXPECT_EQ(typed.exit_code, 3);
  EXPECT_NE(typed.err.find("/part: expected a string"), std::string::npos) << typed.err;
  EXPECT_FALSE(fs::exists(dir_ / "out"));
}

TEST_F(Export, APlanRankBeyondThePlansIsRefused) {
  const fs::path plan = dir_ / "plan";
  ASSERT_EQ(hybridctl({"plan", "--no-validate", (kSource / "examples/parts/overhang.stl").string(), "--machine",
                       (kSource / "examples/machines/hybrid-3axis.yaml").string(), "--voxel", "0.5", "--top", "1", "-o",
                       plan.string()})
                .exit_code,
            0);
  const Outcome r = hybridctl({"export", plan.string(), "--plan", "9", "-o", (dir_ / "out").string()});
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find("--plan 9: expected 1..1"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "out"));
}

}  // namespace
