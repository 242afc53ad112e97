// The plan executor (drivers/executor.hpp) against `hybridctl sim serve` on loopback: a
// program file with our action headings gets its per-action report from the program
// model, the operator is asked at the setup change's program stop with the message before
// it, and a program that fails its check is refused before anything is opened.

#include "drivers/executor.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "common/error.hpp"
#include "config/machine_loader.hpp"
#include "geometry/vdb_file.hpp"
#include "gcode/post.hpp"
#include "sample_programs.hpp"
#include "sim_process.hpp"
#include "transport_fixtures.hpp"

namespace {

namespace fs = std::filesystem;
using namespace hybridctl;

// Answers yes to everything and remembers what it was told.
struct RecordingOperator : drivers::JobOperator {
  bool check_failed_called = false;
  std::optional<drivers::JobStart> job;
  int progress_calls = 0;
  std::vector<std::string> stop_messages;
  void check_failed(const gcode::CheckReport&) override { check_failed_called = true; }
  void started(const drivers::JobStart& j) override { job = j; }
  void progress(const protocol::Status&, const drivers::JobProgress& p) override {
    ++progress_calls;
    EXPECT_LE(p.action, p.actions);
    seen_actions.emplace_back(p.action, p.action_number);
  }
  std::vector<std::pair<std::size_t, int>> seen_actions;  // (index in the program, the plan's number)
  std::vector<std::string> notes;
  void note(const std::string& n) override { notes.push_back(n); }
  bool continue_after_stop(const protocol::Status&, const std::string& message) override {
    stop_messages.push_back(message);
    return true;
  }
  bool clear_alarm(const protocol::Status&) override { return true; }
  bool hold_requested() override { return false; }
  bool resume_after_hold(const protocol::Status&) override { return true; }
};

std::string write_file(const fs::path& path, const std::string& text) {
  std::ofstream(path) << text;
  return path.string();
}

TEST(Executor, AProgramFileReportsPerActionFromItsHeadings) {
  const std::string machine_file = test::example_machine();
  const config::Machine machine = config::load_machine(machine_file);
  // Numbered from 2, as a plan whose first action is its raw stock (no lines) numbers them.
  auto actions = gcode::samples::sample_actions(machine);
  for (auto& a : actions) a.action += 1;
  const gcode::PostedProgram posted = gcode::post_program(actions, machine);
  ASSERT_EQ(posted.actions.front().number, 2);
  const fs::path dir = test::scratch_dir("executor-headings");
  test::SimProcess sim({"--machine", machine_file, "--modbus", "tcp://127.0.0.1:0", "--time-scale", "0", "--exit-when-done"});

  drivers::JobRequest request;
  request.input = write_file(dir / "sample.ngc", posted.text());
  request.machine = machine_file;
  request.transport = "modbus-tcp://127.0.0.1:" + std::to_string(sim.modbus_port());
  request.job = (dir / "job").string();
  RecordingOperator op;
  const drivers::JobResult result = drivers::execute_job(request, op);

  ASSERT_TRUE(result.stream.completed) << result.stream.stopped_because;
  ASSERT_TRUE(op.job.has_value());
  EXPECT_EQ(op.job->lines, posted.lines.size());
  EXPECT_EQ(result.lines, posted.lines.size());
  EXPECT_GT(op.progress_calls, 0);
  // The progress names each action by the plan's number, as its heading does.
  for (const auto& [index, number] : op.seen_actions)
    EXPECT_EQ(number, index == 0 ? 0 : posted.actions[index - 1].number) << "action " << index;
  // The setup change stops for the operator with its message.
  ASSERT_EQ(op.stop_messages.size(), 1u);
  EXPECT_EQ(op.stop_messages[0].rfind("MSG, setup bottom", 0), 0u) << op.stop_messages[0];
  // One report per heading, named by it; the last runs to the program's end.
  ASSERT_EQ(result.actions.size(), posted.actions.size());
  for (std::size_t i = 0; i < result.actions.size(); ++i) {
    const drivers::ActionReport& a = result.actions[i];
    EXPECT_EQ(a.name, posted.actions[i].heading());
    const std::uint32_t last = i + 1 < posted.actions.size() ? posted.actions[i + 1].first_line - 1
                                                               : std::uint32_t(posted.lines.size());
    EXPECT_EQ(a.lines, last - posted.actions[i].first_line + 1);
    EXPECT_EQ(a.executed, a.lines);
    EXPECT_TRUE(a.seconds.has_value());
    EXPECT_TRUE(a.alarms.empty());
  }
  EXPECT_EQ(sim.wait(std::chrono::seconds(20)), 0);
}

TEST(Executor, AWarningOfTheControllerIsReportedWithItsLineAndTheJobGoesOn) {
  const std::string machine_file = test::example_machine();
  const fs::path dir = test::scratch_dir("executor-warning");
  // A plate with a pillar 8 mm high at x [0, 10] and a post far away (the world's height);
  // the DED head lays a track on the pillar and on past its edge into the air (line 7).
  const geometry::Lattice lattice{0.5, {0, 0, 0}};
  geometry::Solid stock = geometry::Solid::filled(lattice, geometry::IndexBox{{0, 0, 0}, {80, 40, 4}});
  stock = geometry::unite(stock, geometry::Solid::filled(lattice, geometry::IndexBox{{0, 0, 4}, {20, 40, 20}}));
  stock = geometry::unite(stock, geometry::Solid::filled(lattice, geometry::IndexBox{{76, 36, 4}, {80, 40, 40}}));
  geometry::write_vdb(stock, dir / "stock.vdb");
  test::SimProcess sim({"--machine", machine_file, "--modbus", "tcp://127.0.0.1:0", "--time-scale", "0", "--exit-when-done",
                        "--stock-vdb", (dir / "stock.vdb").string()});
  drivers::JobRequest request;
  request.input = write_file(dir / "over-air.ngc", "%\nG21 G90\nG54\nT100 M6\nG0 X2 Y10 Z30\nG1 Z10 F800\nM64 P0\n"
                                                   "G1 X20 F800\nM65 P0\nG1 Z30 F800\nM2\n%\n");
  request.machine = machine_file;
  request.transport = "modbus-tcp://127.0.0.1:" + std::to_string(sim.modbus_port());
  request.job = (dir / "job").string();
  RecordingOperator op;
  const drivers::JobResult result = drivers::execute_job(request, op);
  ASSERT_TRUE(result.stream.completed) << result.stream.stopped_because;
  EXPECT_EQ(result.stream.counters.warnings, 1u);
  bool said = false;
  for (const std::string& n : op.notes) said = said || n.rfind("warning DEPOSITION_OVER_AIR at line 8: ", 0) == 0;
  EXPECT_TRUE(said) << "notes: " << ::testing::PrintToString(op.notes);
  EXPECT_EQ(sim.wait(std::chrono::seconds(20)), 0);
}

TEST(Executor, AProgramThatFailsItsCheckIsRefusedBeforeAnythingIsSent) {
  const fs::path dir = test::scratch_dir("executor-check");
  drivers::JobRequest request;
  request.input = write_file(dir / "outside.ngc", "G21 G90\nG54\nG0 X9999 Y0 Z50\nM2\n");
  request.machine = test::example_machine();
  request.transport = "modbus-tcp://127.0.0.1:1";  // never opened
  request.job = (dir / "job").string();
  RecordingOperator op;
  EXPECT_THROW(drivers::execute_job(request, op), InputError);
  EXPECT_TRUE(op.check_failed_called);
  EXPECT_FALSE(op.job.has_value());
  EXPECT_FALSE(fs::exists(dir / "job"));
}

}  // namespace
