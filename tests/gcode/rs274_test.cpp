// LinuxCNC's own interpreter is the judge: `rs274 -t TOOLTABLE -g FILE.ngc` must accept
// every program our post-processor writes for the example machines (exit 0, arcs and
// straight feeds as expected, a program end), with our tool table; and must reject a
// broken program (exit 1, naming the offending line), which proves the harness can fail.
//
// rs274 comes from scripts/setup (unpacked into .peers/linuxcnc, run by scripts/rs274).
// Missing, it is a failure with instructions, not a skip.

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "config/machine_loader.hpp"
#include "gcode/post.hpp"
#include "gcode/tool_table.hpp"
#include "sample_programs.hpp"

namespace {

namespace fs = std::filesystem;
using namespace hybridctl::gcode;
using hybridctl::config::Machine;

const fs::path kSource = HYBRIDCTL_SOURCE_DIR;
const fs::path kRs274 = kSource / "scripts" / "rs274";

struct Rs274Run {
  int exit_code = -1;
  std::string out, err;
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

class Rs274 : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("hybridctl-rs274-" + std::to_string(::getpid()) + "-" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
    ASSERT_TRUE(fs::exists(kSource / ".peers/linuxcnc/usr/bin/rs274"))
        << "LinuxCNC's rs274 is missing from .peers/linuxcnc: run scripts/setup (it downloads linuxcnc-uspace "
           "and libboost-python1.74.0 with apt-get download and unpacks them there)";
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name, std::ios::binary) << text;
    return dir_ / name;
  }

  Rs274Run rs274(const fs::path& tool_table, const fs::path& program) {
    const std::string cmd = "'" + kRs274.string() + "' -t '" + tool_table.string() + "' -g '" + program.string() +
                            "' >'" + (dir_ / "out").string() + "' 2>'" + (dir_ / "err").string() + "' </dev/null";
    const int status = std::system(cmd.c_str());
    Rs274Run r;
    r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    r.out = slurp(dir_ / "out");
    r.err = slurp(dir_ / "err");
    return r;
  }

  static int count(const std::string& text, const std::string& word) {
    int n = 0;
    for (std::size_t at = text.find(word); at != std::string::npos; at = text.find(word, at + 1)) ++n;
    return n;
  }

  /// Every program for `machine` (the whole plan and each action) runs through rs274.
  void expect_accepted(const Machine& machine) {
    const auto actions = samples::sample_actions(machine);
    const fs::path table = write("tool.tbl", linuxcnc_tool_table(machine));
    int arcs = 0;
    for (const auto& a : actions)
      for (const auto& m : a.path.moves) arcs += m.kind == MoveKind::ArcCw || m.kind == MoveKind::ArcCcw;

    const fs::path whole = write("plan.ngc", write_program(actions, machine));
    const Rs274Run r = rs274(table, whole);
    EXPECT_EQ(r.exit_code, 0) << r.err << "\n" << slurp(whole);
    EXPECT_EQ(count(r.out, "ARC_FEED("), arcs) << r.out;
    EXPECT_GT(count(r.out, "STRAIGHT_FEED("), 0);
    EXPECT_EQ(count(r.out, "CHANGE_TOOL("), 4) << r.out;
    EXPECT_EQ(count(r.out, "PROGRAM_END()"), 1) << r.out;
    EXPECT_GT(count(r.out, "SET_AUX_OUTPUT_BIT("), 0) << r.out;  // deposition on (M64)

    for (const auto& a : actions) {
      const fs::path one = write("action-" + std::to_string(a.action) + ".ngc", write_action(a, machine));
      const Rs274Run ra = rs274(table, one);
      EXPECT_EQ(ra.exit_code, 0) << "action " << a.action << ": " << ra.err << "\n" << slurp(one);
      EXPECT_EQ(count(ra.out, "PROGRAM_END()"), 1) << ra.out;
    }
  }

  fs::path dir_;
};

TEST_F(Rs274, AcceptsOurProgramsForTheHybrid3AxisMachine) {
  expect_accepted(hybridctl::config::load_machine(kSource / "examples/machines/hybrid-3axis.yaml"));
}

TEST_F(Rs274, AcceptsOurProgramsForTheBAxisMachineInTheRs274ngcDialect) {
  Machine m = hybridctl::config::load_machine(kSource / "examples/machines/multitask-b-axis.yaml");
  // This machine is Fanuc-style with M203 for its milling spindle; LinuxCNC runs M3.
  m.gcode.dialect = hybridctl::config::Dialect::Rs274ngc;
  m.gcode.m_codes = {};
  expect_accepted(m);
}

TEST_F(Rs274, RejectsABrokenProgramNamingTheLine) {
  const Machine m = hybridctl::config::load_machine(kSource / "examples/machines/hybrid-3axis.yaml");
  std::string text = write_program(samples::sample_actions(m), m);
  // A feed move with zero feed before anything else moves.
  const std::size_t at = text.find("G54\n") + 4;
  text.insert(at, "G1 X1 F0\n");
  const Rs274Run r = rs274(write("tool.tbl", linuxcnc_tool_table(m)), write("broken.ngc", text));
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_NE(r.err.find("Cannot do g1 with zero feed rate"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("G1 X1 F0"), std::string::npos) << r.err;

  // An arc whose radii differ by 1 mm.
  const Rs274Run arc = rs274(write("tool.tbl", linuxcnc_tool_table(m)),
                             write("arc.ngc", "G21 G90 G17\nG0 X0 Y0 Z5\nG2 X10 Y0 I4 J0 F100\nM2\n"));
  EXPECT_EQ(arc.exit_code, 1);
  EXPECT_NE(arc.err.find("Radius to end of arc differs from radius to start"), std::string::npos) << arc.err;
  EXPECT_NE(arc.err.find("G2 X10 Y0 I4 J0 F100"), std::string::npos) << arc.err;
}

}  // namespace
