// `hybridctl cell machine-host` (docs/cell.md, "Machine hosts") against a real PostgreSQL
// server of the test's own and `hybridctl sim serve` as the machine's controller, each a
// separate process on 127.0.0.1: a host killed mid-program, the job resumed by another
// host process once the first one's lease ran out, with every line executed exactly once
// on the simulated controller and the job never taken by another machine's host; the
// database restarted mid-stream; bad input refused.

#include <regex>

#include "cell_fixture.hpp"

namespace hybridctl::cell {
namespace {

namespace fs = std::filesystem;
using cell_testing::CellTest;
using cell_testing::kSource;
using cell_testing::Process;
using cli_testing::quote;
using cli_testing::slurp;

class MachineHost : public CellTest {
 protected:
  MachineHost() : CellTest("machine-host") {}

  // A 60 x 40 x 20 mm box, planned by a plan worker; its plan directory in dir_/job.
  std::int64_t planned_job() {
    init_with_a_machine();
    const fs::path part = dir_ / "block.stl";
    cell_testing::write_box(part, 60, 40, 20);
    const std::int64_t job = submit(part, "--voxel 2 --top 1");
    Process worker(worker_command("--drain"), dir_ / "worker.out");
    EXPECT_EQ(worker.wait(600), 0) << slurp(dir_ / "worker.out");
    EXPECT_EQ(value("SELECT state FROM cell_jobs WHERE id = " + std::to_string(job)), "planned") << slurp(dir_ / "worker.out");
    const auto files = cell("report " + std::to_string(job) + " -o " + quote((dir_ / "job").string()));
    EXPECT_EQ(files.exit_code, 0) << files.err;
    return job;
  }

  // The simulated controller for the job's stock, at `time_scale` times real time, logging
  // every line it executes; registered as the machine's controller.
  // `name`: its output in NAME.out, its executed lines in NAME.ngc; `port` 0: any free one;
  // without `stock`, a controller that comes up after a power loss (the part is not its
  // subject).
  std::unique_ptr<Process> controller(const std::string& time_scale, const std::string& name = "lines", int port = 0,
                                      bool stock = true) {
    auto sim = std::make_unique<Process>(
        quote(HYBRIDCTL_EXE) + " sim serve --machine " + quote((kSource / "examples/machines/hybrid-3axis.yaml").string()) +
            (stock ? " --stock " + quote((dir_ / "job" / "plan.json").string()) : std::string()) + " --line-log " +
            quote((dir_ / (name + ".ngc")).string()) + " --exit-when-done --modbus tcp://127.0.0.1:" + std::to_string(port) +
            " --time-scale " + time_scale,
        dir_ / (name + ".out"));
    const bool given = port != 0;
    port = 0;
    for (int i = 0; i < 600 && !port; ++i) {
      std::smatch m;
      const std::string out = slurp(dir_ / (name + ".out"));
      if (std::regex_search(out, m, std::regex("listening modbus-tcp 127\\.0\\.0\\.1:([0-9]+)")) && out.find("ready") != std::string::npos)
        port = std::stoi(m[1]);
      if (!port) std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    EXPECT_GT(port, 0) << slurp(dir_ / (name + ".out"));
    if (given) return sim;
    const auto added = cell("machines add mill --machine " + quote((kSource / "examples/machines/hybrid-3axis.yaml").string()) +
                            " --transport modbus-tcp://127.0.0.1:" + std::to_string(port));
    EXPECT_EQ(added.exit_code, 0) << added.err;
    return sim;
  }

  std::string host_command(const std::string& args) const {
    return quote(HYBRIDCTL_EXE) + " cell machine-host --machine mill " + args + " --db " + quote(server_->uri());
  }

  // The simulated controller executed the job's program, every line once, in order.
  void expect_every_line_once(Process& sim, std::int64_t job, const std::string& name = "lines") {
    EXPECT_EQ(sim.wait(60), 0) << slurp(dir_ / (name + ".out"));
    const std::string program = value("SELECT program FROM cell_streams WHERE job = " + std::to_string(job));
    const std::string log = slurp(dir_ / (name + ".ngc"));
    EXPECT_GT(std::count(program.begin(), program.end(), '\n'), 200);
    EXPECT_TRUE(log == program) << "the controller executed " << std::count(log.begin(), log.end(), '\n')
                                << " lines; the program has " << std::count(program.begin(), program.end(), '\n');
    EXPECT_EQ(value("SELECT state FROM cell_jobs WHERE id = " + std::to_string(job)), "done");
  }

  std::string executed_line(std::int64_t job) {
    return value("SELECT executed_line FROM cell_streams WHERE job = " + std::to_string(job));
  }
  // Waits until the controller has executed more than `line` lines of the job (at most
  // 5 min: the host proves the plan first, slowly under the sanitizers).
  bool executed_past(std::int64_t job, int line) {
    for (int i = 0; i < 6000; ++i) {
      const std::string executed = executed_line(job);
      if (!executed.empty() && std::stoi(executed) > line) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    return false;
  }
};

TEST_F(MachineHost, AHostKilledMidProgramIsResumedByAnotherAndEveryLineRunsOnce) {
  const std::int64_t job = planned_job();
  auto sim = controller("20");
  auto first = std::make_unique<Process>(host_command("--name first --lease 15 --yes --drain"), dir_ / "first.out");
  ASSERT_TRUE(executed_past(job, 20)) << slurp(dir_ / "first.out");
  kill(first->pid, SIGKILL);
  first->wait(10);
  ASSERT_NE(value("SELECT state FROM cell_jobs WHERE id = " + std::to_string(job)), "done") << "the host finished before it was killed";

  // Another machine's host never takes the job: it stays bound to its machine.
  ASSERT_EQ(cell("machines add lathe --machine " + quote((kSource / "examples/machines/hybrid-3axis.yaml").string()) +
                 " --transport modbus-tcp://127.0.0.1:1")
                .exit_code,
            0);
  Process other(quote(HYBRIDCTL_EXE) + " cell machine-host --machine lathe --name other --yes --drain --db " + quote(server_->uri()),
                dir_ / "other.out");
  EXPECT_EQ(other.wait(60), 0) << slurp(dir_ / "other.out");
  EXPECT_EQ(value("SELECT state || ' ' || machine FROM cell_jobs WHERE id = " + std::to_string(job)), "streaming mill");

  // The first host's lease (15 s) still holds the machine when the second starts, after
  // the other machine's host has come and gone (3 s was over by then under the
  // sanitizers), and the second waits it out. The second's is the others' 20 s: a host
  // stops streaming when its journal has not been written for half its lease, and on a
  // loaded machine (two cores, the cell's four planning workers beside it) 1.5 s went by.
  Process second(host_command("--name second --lease 20 --yes --drain"), dir_ / "second.out");
  EXPECT_EQ(second.wait(600), 0) << slurp(dir_ / "second.out");
  const std::string said = slurp(dir_ / "second.out");
  EXPECT_NE(said.find("machine mill is driven by host first"), std::string::npos) << said;
  EXPECT_NE(said.find("resuming (last streamed by first"), std::string::npos) << said;
  expect_every_line_once(*sim, job);
  EXPECT_EQ(value("SELECT string_agg(worker || ':' || event, ' ' ORDER BY id) FROM cell_job_events "
                  "WHERE event IN ('bound', 'done')"),
            "first:bound second:done");
}

TEST_F(MachineHost, TheDatabaseRestartedMidStreamLosesNoLineAndRunsNoneTwice) {
  const std::int64_t job = planned_job();
  auto sim = controller("20");
  Process host(host_command("--name steady --lease 20 --yes --drain"), dir_ / "host.out");
  ASSERT_TRUE(executed_past(job, 20)) << slurp(dir_ / "host.out");
  server_->stop();
  std::this_thread::sleep_for(std::chrono::seconds(2));
  server_->start();
  EXPECT_EQ(host.wait(600), 0) << slurp(dir_ / "host.out");
  expect_every_line_once(*sim, job);
  EXPECT_NE(slurp(dir_ / "host.out").find("database back"), std::string::npos) << slurp(dir_ / "host.out");
}

// A controller power cycle mid-program: the host stops, says what ran and the command that
// goes on; that command restarts the job's program at the safe point on the new boot.
TEST_F(MachineHost, AControllerPowerLossStopsTheHostAndFromLineRestartsTheJobOnce) {
  const std::int64_t job = planned_job();
  auto first = controller("20", "sim1");
  const std::string port = value("SELECT substring(transport from '[0-9]+$') FROM cell_machines WHERE name = 'mill'");
  Process host(host_command("--name steady --lease 20 --yes --drain"), dir_ / "host.out");
  ASSERT_TRUE(executed_past(job, 100)) << slurp(dir_ / "host.out");
  kill(first->pid, SIGKILL);
  first->wait(5);
  for (int i = 0; i < 1200 && slurp(dir_ / "host.out").find("waiting for it to come back") == std::string::npos; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  auto second = controller("0", "sim2", std::stoi(port), false);
  EXPECT_EQ(host.wait(60), 5) << slurp(dir_ / "host.out");
  const std::string out = slurp(dir_ / "host.out");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(out, m, std::regex(R"(hybridctl cell machine-host --machine mill --from-line (\d+))"))) << out;
  const std::string from = m[1];
  EXPECT_EQ(value("SELECT lost FROM cell_streams WHERE job = " + std::to_string(job)), "t");
  EXPECT_EQ(value("SELECT state FROM cell_jobs WHERE id = " + std::to_string(job)), "streaming");
  EXPECT_NE(value("SELECT reason FROM cell_jobs WHERE id = " + std::to_string(job)).find("controller lost the program"), std::string::npos);
  const std::string original = value("SELECT original FROM cell_streams WHERE job = " + std::to_string(job));

  Process restart(host_command("--name steady --from-line " + from + " --yes --drain"), dir_ / "restart.out");
  EXPECT_EQ(restart.wait(120), 0) << slurp(dir_ / "restart.out");
  // The new boot ran the restart (a preamble, then lines N..end of the original), each once.
  expect_every_line_once(*second, job, "sim2");
  const std::string program = value("SELECT program FROM cell_streams WHERE job = " + std::to_string(job));
  EXPECT_EQ(program.rfind("(restart at line " + from + ":", 0), 0u) << program.substr(0, 200);
  std::size_t at = 0;
  for (int l = 1; l < std::stoi(from); ++l) at = original.find('\n', at) + 1;
  const std::string rest = original.substr(at);
  ASSERT_GE(program.size(), rest.size());
  EXPECT_EQ(program.compare(program.size() - rest.size(), rest.size(), rest), 0) << "the restart ends with lines N..end";
}

TEST_F(MachineHost, BadInputIsRefusedWithWhereAndWhat) {
  init_with_a_machine();
  const auto unknown = cell("machine-host --machine lathe --yes");
  EXPECT_EQ(unknown.exit_code, 3);
  EXPECT_NE(unknown.err.find("--machine lathe"), std::string::npos) << unknown.err;
  const auto no_controller = cell("machine-host --machine mill --yes");
  EXPECT_EQ(no_controller.exit_code, 3);
  EXPECT_NE(no_controller.err.find("--transport"), std::string::npos) << no_controller.err;
  const auto nothing_bound = cell("machine-host --machine mill --from-line 12 --transport modbus-tcp://127.0.0.1:1 --yes");
  EXPECT_EQ(nothing_bound.exit_code, 3);
  EXPECT_NE(nothing_bound.err.find("no job bound"), std::string::npos) << nothing_bound.err;
  // A planned job and no operator: not streamed without --yes.
  submit(box_);
  Process worker(worker_command("--drain"), dir_ / "worker.out");
  ASSERT_EQ(worker.wait(600), 0) << slurp(dir_ / "worker.out");
  const auto unattended = cell("machine-host --machine mill --transport modbus-tcp://127.0.0.1:1");
  EXPECT_EQ(unattended.exit_code, 3);
  EXPECT_NE(unattended.err.find("--yes"), std::string::npos) << unattended.err;
  EXPECT_EQ(value("SELECT state FROM cell_jobs"), "planned");
  const auto bad_lease = cell("machine-host --machine mill --lease 0.5 --yes");
  EXPECT_EQ(bad_lease.exit_code, 2) << bad_lease.err;
}

}  // namespace
}  // namespace hybridctl::cell
