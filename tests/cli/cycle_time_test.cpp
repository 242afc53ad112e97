// One cycle time (docs/gcode.md, "The time model"): `plan`, `export`, `gcode check` and
// `dry-run` (which streams as `run` does) print the same time for the same program, each
// with what it includes.

#include <gtest/gtest.h>

#include <regex>
#include <string>

#include "shell.hpp"

namespace {

using hybridctl::cli_testing::Outcome;

class CycleTime : public hybridctl::cli_testing::DirectoryTest {
 protected:
  CycleTime() : DirectoryTest("cycle-time") {}
};

const std::string kSource = HYBRIDCTL_SOURCE_DIR;
const std::string kFlangedHub = kSource + "/examples/parts/flanged-hub.stl";
const std::string kHybrid = kSource + "/examples/machines/hybrid-3axis.yaml";

// The text after `prefix` up to the end of its line: "31 min 58.7 s: motion ...".
std::string after(const std::string& out, const std::string& prefix) {
  const std::size_t at = out.find(prefix);
  if (at == std::string::npos) return "";
  const std::size_t from = at + prefix.size();
  return out.substr(from, out.find('\n', from) - from);
}

// The cycle time's own words, without what a command adds after them.
std::string cycle_time_of(const std::string& line) {
  static const std::regex time("^([0-9][^:]*: motion .*?)( \\(its program, as export writes it\\))?$");
  std::smatch m;
  return std::regex_match(line, m, time) ? std::string(m[1]) : "";
}

// The flanged hub's best plan mills it from the bottom, then re-clamps it for the top: its
// time holds the motion, the tool loaded and the refixture, and every command says so.
TEST_F(CycleTime, PlanExportGcodeCheckAndTheRunPrintTheSameTimeForOneProgram) {
  const std::string exported = (dir_ / "ngc").string();
  const Outcome plan = run_hybridctl({"plan", kFlangedHub, "-m", kHybrid, "-o", (dir_ / "plan").string(), "--top",
                                      "1", "--export", exported});
  ASSERT_EQ(plan.exit_code, 0) << plan.err << plan.out;
  const std::string planned = cycle_time_of(after(plan.out, "\n     cycle time: "));
  ASSERT_FALSE(planned.empty()) << plan.out;
  EXPECT_NE(planned.find("motion "), std::string::npos) << planned;
  EXPECT_NE(planned.find("1 refixture 15 min 00.0 s"), std::string::npos) << planned;
  EXPECT_NE(planned.find("tool change"), std::string::npos) << planned;

  EXPECT_EQ(after(plan.out, "\ncycle time  plan-1.ngc: "), planned) << plan.out;

  const Outcome check = run_hybridctl({"gcode", "check", exported + "/plan-1.ngc", "-m", kHybrid});
  ASSERT_EQ(check.exit_code, 0) << check.err << check.out;
  EXPECT_EQ(after(check.out, "\ncycle time: "), planned) << check.out;

  const Outcome dry = run_hybridctl({"dry-run", kFlangedHub, "-m", kHybrid, "-o", (dir_ / "dry").string()});
  ASSERT_EQ(dry.exit_code, 0) << dry.err << dry.out;
  EXPECT_EQ(after(dry.out, "\ncycle time  "), planned) << dry.out;

  // Per action, `plan` and `export` print the same motion of its own program.
  static const std::regex action_motion("remove +[0-9.]+ mm³ +cost [^\\n]*; motion ([^)]*)\\)");
  std::smatch m;
  const std::string plan_out = plan.out;
  ASSERT_TRUE(std::regex_search(plan_out, m, action_motion)) << plan.out;
  EXPECT_NE(plan.out.find("moves  motion " + std::string(m[1]) + "  -> plan-1-action-02.ngc"), std::string::npos)
      << plan.out;
}

}  // namespace
