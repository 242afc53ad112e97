// Arcs in the exported programs, end to end (docs/toolpaths.md, "Arc fitting"): the flanged
// hub's plans from the ctest fixture Fixture.PlanFlangedHub (tests/CMakeLists.txt) executed
// as export executes them, once with arcs fitted (the default) and once with the
// generators' G1 chords only. With arcs:
//  - the program holds G2/G3 moves, fewer lines and bytes, in both dialects;
//  - LinuxCNC's own interpreter (rs274, scripts/rs274, unpacked by scripts/setup) accepts
//    it, reading one ARC_FEED per arc we wrote;
//  - the plan is proven as before, and its exact verification against the STL (excess and
//    gouge) is the same within 0.001 mm: the arcs lie within the finishing's own accuracy.
// The figures are printed (program sizes before and after, the exact deviation).

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "gcode/post.hpp"
#include "gcode/tool_table.hpp"
#include "plan/plan_machine.hpp"
#include "validation/execution.hpp"

namespace {

namespace fs = std::filesystem;
using namespace hybridctl;

const fs::path kSource = HYBRIDCTL_SOURCE_DIR;

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

int count(const std::string& text, const std::string& word) {
  int n = 0;
  for (std::size_t at = text.find(word); at != std::string::npos; at = text.find(word, at + 1)) ++n;
  return n;
}

// Lines that are arc moves: "G2 ..."/"G3 ..." (rs274ngc) or "N.. G2 ..." (fanuc).
int arc_lines(const std::vector<std::string>& lines) {
  int n = 0;
  for (const std::string& l : lines) {
    std::string_view v(l);
    if (v.starts_with("N")) v.remove_prefix(std::min(v.size(), v.find(' ') + 1));
    n += v.starts_with("G2 ") || v.starts_with("G3 ");
  }
  return n;
}

std::size_t bytes(const gcode::PostedProgram& p) { return p.text().size(); }

class ArcExport : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("hybridctl-arcs-" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    ASSERT_TRUE(fs::exists(kSource / ".peers/linuxcnc/usr/bin/rs274"))
        << "LinuxCNC's rs274 is missing from .peers/linuxcnc: run scripts/setup";
    const fs::path plan = fs::path(HYBRIDCTL_HUB_PLAN) / "plan.json";
    ASSERT_TRUE(fs::exists(plan)) << plan << ": not planned; run this test with ctest, whose fixture Fixture.PlanFlangedHub plans it";
    file_ = plan::read_plan_file(plan.string());
    machine_ = plan::plan_machine(file_, {}).machine;
  }
  void TearDown() override { fs::remove_all(dir_); }

  // rs274's exit code and its canonical calls for `text`.
  std::pair<int, std::string> rs274(const std::string& text, const std::string& name) {
    std::ofstream(dir_ / name, std::ios::binary) << text;
    std::ofstream(dir_ / "tool.tbl", std::ios::binary) << gcode::linuxcnc_tool_table(machine_);
    const std::string cmd = "'" + (kSource / "scripts/rs274").string() + "' -t '" + (dir_ / "tool.tbl").string() + "' -g '" +
                            (dir_ / name).string() + "' >'" + (dir_ / "out").string() + "' 2>'" + (dir_ / "err").string() +
                            "' </dev/null";
    const int status = std::system(cmd.c_str());
    const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    return {code, slurp(dir_ / "out") + (code ? "\n" + slurp(dir_ / "err") : "")};
  }

  fs::path dir_;
  plan::PlanFile file_;
  config::Machine machine_;
};

TEST_F(ArcExport, TheFlangedHubsProgramsHaveArcsThatRs274AcceptsAndVerifyAsTheLinesDid) {
  int plans_with_arcs = 0;
  for (std::size_t rank = 1; rank <= file_.plans.size(); ++rank) {
    const plan::PlanFilePlan& plan = file_.plans[rank - 1];
    validation::ExecutionOptions lines_only;
    lines_only.export_options.arcs.output = toolpaths::ArcOutput::Lines;
    const validation::Execution arcs = validation::execute_plan(file_, plan, machine_);
    const validation::Execution lines = validation::execute_plan(file_, plan, machine_, lines_only);
    ASSERT_TRUE(arcs.proven()) << "plan " << rank << ":\n" << validation::describe_reasons(arcs.reasons);
    ASSERT_TRUE(lines.proven()) << "plan " << rank << ":\n" << validation::describe_reasons(lines.reasons);
    EXPECT_EQ(arc_lines(lines.program.lines), 0) << "plan " << rank << ": the generators make no arcs themselves";

    const int arc_count = arc_lines(arcs.program.lines);
    plans_with_arcs += arc_count > 0;
    std::printf("plan %zu (%s): rs274ngc %zu lines %zu bytes with lines only, %zu lines %zu bytes with %d arcs\n", rank,
                plan.expression.c_str(), lines.program.lines.size(), bytes(lines.program), arcs.program.lines.size(),
                bytes(arcs.program), arc_count);
    if (arc_count > 0) {
      EXPECT_LT(arcs.program.lines.size(), lines.program.lines.size()) << "plan " << rank;
      EXPECT_LT(bytes(arcs.program), bytes(lines.program)) << "plan " << rank;
    }

    // LinuxCNC reads every arc we wrote, and the program to its end.
    const auto [code, canonical] = rs274(arcs.program.text(), "plan-" + std::to_string(rank) + ".ngc");
    EXPECT_EQ(code, 0) << "plan " << rank << "\n" << canonical.substr(canonical.size() > 3000 ? canonical.size() - 3000 : 0);
    EXPECT_EQ(count(canonical, "ARC_FEED("), arc_count) << "plan " << rank;
    EXPECT_EQ(count(canonical, "PROGRAM_END()"), 1) << "plan " << rank;

    // The other dialect writes the same arcs; its post-processor runs our interpreter over
    // every line (LinuxCNC's radius check included) and throws on a refused one.
    gcode::PostOptions fanuc;
    fanuc.dialect = config::Dialect::Fanuc;
    const gcode::PostedProgram fanuc_arcs = gcode::post_program(arcs.exported.programs(), machine_, fanuc);
    const gcode::PostedProgram fanuc_lines = gcode::post_program(lines.exported.programs(), machine_, fanuc);
    EXPECT_EQ(arc_lines(fanuc_arcs.lines), arc_count) << "plan " << rank;
    std::printf("          fanuc %zu lines %zu bytes with lines only, %zu lines %zu bytes with arcs\n",
                fanuc_lines.lines.size(), bytes(fanuc_lines), fanuc_arcs.lines.size(), bytes(fanuc_arcs));

    // The part made, measured against the STL, is the same within 0.001 mm.
    ASSERT_TRUE(arcs.exact && lines.exact) << "plan " << rank << ": no exact verification";
    std::printf("          exact: lines only excess %.4f gouge %.4f mm; arcs excess %.4f gouge %.4f mm\n",
                lines.exact->excess.mm, lines.exact->gouge.mm, arcs.exact->excess.mm, arcs.exact->gouge.mm);
    EXPECT_NEAR(arcs.exact->excess.mm, lines.exact->excess.mm, 0.001) << "plan " << rank;
    EXPECT_NEAR(arcs.exact->gouge.mm, lines.exact->gouge.mm, 0.001) << "plan " << rank;
    EXPECT_NEAR(arcs.deviation.worst_distance, lines.deviation.worst_distance, 1e-9) << "plan " << rank << ": on the voxels";
  }
  EXPECT_GE(plans_with_arcs, 1) << "the hub's round walls are finished with arcs in at least its best plan";
}

}  // namespace
