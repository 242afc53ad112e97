// hybridctl run and dry-run end to end: the flanged hub's best plan streamed to a simulated
// controller, a separate `hybridctl sim serve` process on 127.0.0.1, over Modbus TCP, Modbus
// RTU (socat pty pair) and socketcand, also under fault injection and after the host is
// killed. The simulator's line log must equal the program: every line once, in order.

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include "../sanitizer_report.hpp"
#include "shell.hpp"

#include <chrono>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <thread>

namespace {

namespace fs = std::filesystem;
const fs::path kSource = HYBRIDCTL_SOURCE_DIR;
const std::string kMachine = (kSource / "examples/machines/hybrid-3axis.yaml").string();

using hybridctl::cli_testing::quote;
using hybridctl::cli_testing::slurp;

// How long a background process may take to say it is up (sim serve loads the plan's stock
// first; several times slower in the sanitizer build), in 50 ms polls: 20 s, as
// tests/sim/wire/sim_process.hpp waits for sim serve's ready line.
constexpr int kStartupPolls = 400;
// How long `run` may take to start streaming a plan: it exports the plan's program and
// proves it on the simulated machine first (exact verification included), which the
// sanitizer build on a slow machine takes tens of seconds for: 3 min in 50 ms polls.
constexpr int kProvingPolls = 3600;

// Waits until the host's status line (in `err`) says `state`, at most kProvingPolls.
void wait_until_streaming(const fs::path& err, const std::string& state = "RUNNING") {
  for (int i = 0; i < kProvingPolls && slurp(err).find(state) == std::string::npos; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
}

std::string command(const std::vector<std::string>& args) {
  std::string cmd = quote(HYBRIDCTL_EXE);
  for (const auto& a : args) cmd += " " + quote(a);
  return cmd;
}

// A background process started by the shell; its pid from `$!`.
struct Background {
  pid_t pid = -1;
  Background(const std::string& cmd, const fs::path& dir, const std::string& name) {
    const fs::path pidfile = dir / (name + ".pid");
    const std::string sh = cmd + " >" + quote((dir / (name + ".out")).string()) + " 2>" + quote((dir / (name + ".err")).string()) +
                           " </dev/null & echo $! >" + quote(pidfile.string());
    EXPECT_EQ(std::system(sh.c_str()), 0);
    pid = std::stoi(slurp(pidfile));
  }
  bool alive() const { return ::kill(pid, 0) == 0; }
  void wait_exit(double seconds) const {
    for (int i = 0; i < int(seconds * 20) && alive(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  // SIGTERM, and its end awaited so that what it writes at exit (its report, a sanitizer's)
  // is there before the test's directory is read and removed.
  ~Background() {
    if (alive()) ::kill(pid, SIGTERM);
    wait_exit(15);
  }
};

class Run : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = hybridctl::cli_testing::test_directory("run");
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  // The processes' stderr (*.err; dry-run's sim.log) carries no sanitizer report (the
  // sanitizer build): a simulator started with `&` is not our child, so its exit status is
  // not ours to check.
  void TearDown() override {
    for (const auto& entry : fs::recursive_directory_iterator(dir_)) {
      if (entry.path().extension() != ".err" && entry.path().extension() != ".log") continue;
      const std::string report = hybridctl::test::sanitizer_report(slurp(entry.path()));
      EXPECT_TRUE(report.empty()) << "sanitizer report in " << entry.path().filename().string() << ":\n" << report;
    }
    fs::remove_all(dir_);
  }

  // The flanged hub planned once at 0.5 mm for every test (the ctest fixture
  // Fixture.PlanFlangedHub, tests/CMakeLists.txt), read-only. Three plans, each proven by
  // execution: the raw plate milled from below, the part turned over by hand (a program
  // stop), then milled from above; the third mills with T1, then T2. (The bracket has no
  // plan on this machine: the roof of its horizontal hole can be neither deposited nor
  // milled from above or below.)
  static fs::path plan() {
    const fs::path p = fs::path(HYBRIDCTL_HUB_PLAN) / "plan.json";
    EXPECT_TRUE(fs::exists(p)) << p << ": not planned; run these tests with ctest, whose fixture Fixture.PlanFlangedHub plans it";
    return p;
  }

  // `hybridctl sim serve` with `extra` flags, the plan's stock and a line log; returns
  // the endpoint it listens on (`what`: modbus-tcp or socketcand).
  std::unique_ptr<Background> serve(std::vector<std::string> extra, const std::string& what, int& port,
                                    bool exit_when_done = true) {
    std::vector<std::string> args = {"sim", "serve", "--machine", kMachine, "--stock", plan().string(),
                                     "--line-log", (dir_ / "lines.ngc").string(), "--report", (dir_ / "report.json").string()};
    if (exit_when_done) args.push_back("--exit-when-done");
    args.insert(args.end(), extra.begin(), extra.end());
    auto sim = std::make_unique<Background>(command(args), dir_, "sim");
    port = 0;
    for (int i = 0; i < kStartupPolls && !port; ++i) {
      std::smatch m;
      const std::string out = slurp(dir_ / "sim.out");
      if (std::regex_search(out, m, std::regex("listening " + what + " 127\\.0\\.0\\.1:([0-9]+)"))) port = std::stoi(m[1]);
      if (!port) std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    EXPECT_GT(port, 0) << slurp(dir_ / "sim.err");
    return sim;
  }

  int run(const std::vector<std::string>& args) {
    const std::string cmd = command(args) + " >>" + quote((dir_ / "run.out").string()) + " 2>>" +
                            quote((dir_ / "run.err").string()) + " </dev/null";
    const int status = std::system(cmd.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  }

  // Every line of the program exactly once, in order: the simulator's log is the program.
  void expect_exactly_once(const Background& sim) {
    sim.wait_exit(10);
    const std::string program = slurp(dir_ / "job" / "program.ngc"), log = slurp(dir_ / "lines.ngc");
    EXPECT_GT(program.size(), 30000u);
    EXPECT_TRUE(log == program) << "the simulator executed " << std::count(log.begin(), log.end(), '\n') << " lines; the program has "
                                << std::count(program.begin(), program.end(), '\n') << "\n"
                                << slurp(dir_ / "run.err").substr(0, 3000);
  }

  fs::path dir_;
};

TEST_F(Run, TheBestPlanOverModbusTcp) {
  int port = 0;
  auto sim = serve({"--modbus", "tcp://127.0.0.1:0", "--time-scale", "0"}, "modbus-tcp", port);
  EXPECT_EQ(run({"run", plan().string(), "--machine", kMachine, "--transport", "modbus-tcp://127.0.0.1:" + std::to_string(port),
                 "--job", (dir_ / "job").string(), "--yes"}),
            0)
      << slurp(dir_ / "run.err");
  expect_exactly_once(*sim);
  // Every line the controller executes, executed: the program's closing "%" is no block.
  const std::string out = slurp(dir_ / "run.out");
  EXPECT_TRUE(std::regex_search(out, std::regex(R"(completed after (\d+) of \1 lines)"))) << out;
  const std::regex action_line(R"(\n  action \d+: .* (\d+)/(\d+) lines)");
  std::smatch last;
  for (std::sregex_iterator it(out.begin(), out.end(), action_line), end; it != end; ++it) last = *it;
  ASSERT_FALSE(last.empty()) << out;
  EXPECT_EQ(last[1], last[2]) << out;
}

// A plan directory copied elsewhere runs from a third directory with the machine it embeds,
// which the job directory keeps for a resume.
TEST_F(Run, ACopiedPlanRunsFromAnotherDirectoryWithItsEmbeddedMachine) {
  fs::create_directories(dir_ / "copy");
  fs::create_directories(dir_ / "cwd");
  fs::copy(plan().parent_path(), dir_ / "copy" / "plan", fs::copy_options::recursive);
  int port = 0;
  auto sim = serve({"--modbus", "tcp://127.0.0.1:0", "--time-scale", "0"}, "modbus-tcp", port);
  const std::string cmd = "cd " + quote((dir_ / "cwd").string()) + " && " +
                          command({"run", "../copy/plan/plan.json", "--transport", "modbus-tcp://127.0.0.1:" + std::to_string(port),
                                   "--job", (dir_ / "job").string(), "--yes"}) +
                          " >" + quote((dir_ / "run.out").string()) + " 2>" + quote((dir_ / "run.err").string()) + " </dev/null";
  EXPECT_EQ(std::system(cmd.c_str()), 0) << slurp(dir_ / "run.err");
  expect_exactly_once(*sim);
  EXPECT_EQ(slurp(dir_ / "job" / "machine.yaml"), slurp(kMachine));
}

TEST_F(Run, TheBestPlanOverSocketcand) {
  int port = 0;
  auto sim = serve({"--socketcand", "127.0.0.1:0", "--time-scale", "0"}, "socketcand", port);
  EXPECT_EQ(run({"run", plan().string(), "--machine", kMachine, "--transport",
                 "socketcand://127.0.0.1:" + std::to_string(port) + "/can0", "--job", (dir_ / "job").string(), "--yes"}),
            0)
      << slurp(dir_ / "run.err");
  expect_exactly_once(*sim);
}

TEST_F(Run, ConnectionsDroppedEveryTenRequests) {
  int port = 0;
  auto sim = serve({"--modbus", "tcp://127.0.0.1:0", "--time-scale", "0", "--drop-every", "10"}, "modbus-tcp", port);
  EXPECT_EQ(run({"run", plan().string(), "--machine", kMachine, "--transport", "modbus-tcp://127.0.0.1:" + std::to_string(port),
                 "--job", (dir_ / "job").string(), "--yes"}),
            0)
      << slurp(dir_ / "run.err");
  expect_exactly_once(*sim);
  const std::string out = slurp(dir_ / "run.out");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(out, m, std::regex("([0-9]+) reconnects"))) << out;
  EXPECT_GE(std::stoi(m[1]), 15) << "the drops did happen and were recovered from";
}

TEST_F(Run, ASimulatorRebootMidActionResumesAtTheSafePoint) {
  int port = 0;
  auto sim = serve({"--modbus", "tcp://127.0.0.1:0", "--time-scale", "0", "--reboot-after-lines", "2000"}, "modbus-tcp", port);
  EXPECT_EQ(run({"run", plan().string(), "--machine", kMachine, "--transport", "modbus-tcp://127.0.0.1:" + std::to_string(port),
                 "--job", (dir_ / "job").string(), "--yes"}),
            0)
      << slurp(dir_ / "run.err");
  expect_exactly_once(*sim);
  // The host says what happened and where it resumed.
  EXPECT_NE(slurp(dir_ / "run.err").find("controller restarted (boot 2): its buffer was lost; resending from line 2001"),
            std::string::npos)
      << slurp(dir_ / "run.err");
  // The final report puts the alarm on the action it struck, with the action's lines and time.
  const std::string out = slurp(dir_ / "run.out");
  EXPECT_TRUE(std::regex_search(out, std::regex(R"(  action 2: .* (\d+)/\1 lines  ran [0-9.]+ s  alarms CONTROLLER_RESTARTED\n)"))) << out;
}

// Two tools and a setup change, each action planned against the stock as the actions before
// it left it: every rapid clears the material really there, so the program runs to its end
// without RAPID_INTO_MATERIAL and with every line once.
TEST_F(Run, APlanWithTwoToolsRunsToItsEndOnTheStockAsMilled) {
  int port = 0;
  auto sim = serve({"--modbus", "tcp://127.0.0.1:0", "--time-scale", "0", "--plan", "3"}, "modbus-tcp", port);
  EXPECT_EQ(run({"run", plan().string(), "--plan", "3", "--machine", kMachine, "--transport",
                 "modbus-tcp://127.0.0.1:" + std::to_string(port), "--job", (dir_ / "job").string(), "--yes"}),
            0)
      << slurp(dir_ / "run.out") << slurp(dir_ / "run.err");
  expect_exactly_once(*sim);
  const std::string out = slurp(dir_ / "run.out");
  std::set<std::string> tools;
  static const std::regex milling("subtractive milling with (T[0-9]+)");
  for (std::sregex_iterator it(out.begin(), out.end(), milling), end; it != end; ++it) tools.insert((*it)[1]);
  EXPECT_GE(tools.size(), 2u) << out;
  const std::string report = slurp(dir_ / "report.json");
  EXPECT_TRUE(std::regex_search(report, std::regex(R"("final_status":\s*\{[^}]*"state":\s*"COMPLETED")"))) << report;
}

// A third of the requests dropped at random (and replies damaged and late, and two
// reboots): runs of failures longer than the transport's own resends happen, and the
// stream rides them out from the controller's status instead of giving up.
TEST_F(Run, HeavyRandomFaultsAreRiddenOutExactlyOnce) {
  int port = 0;
  auto sim = serve({"--modbus", "tcp://127.0.0.1:0", "--time-scale", "0", "--fault-seed", "11", "--drop-every", "3",
                    "--corrupt-every", "40", "--delay-ms", "2", "--reboot-after-lines", "1000,2500"},
                   "modbus-tcp", port);
  EXPECT_EQ(run({"run", plan().string(), "--machine", kMachine, "--transport", "modbus-tcp://127.0.0.1:" + std::to_string(port),
                 "--job", (dir_ / "job").string(), "--yes"}),
            0)
      << slurp(dir_ / "run.err");
  expect_exactly_once(*sim);
  const std::string out = slurp(dir_ / "run.out");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(out, m, std::regex("([0-9]+) link failures recovered"))) << out;
  EXPECT_GE(std::stoi(m[1]), 1) << "no request failed beyond the transport's resends: the fault rate is too low to test this";
  ASSERT_TRUE(std::regex_search(out, m, std::regex("([0-9]+) reboots seen"))) << out;
  EXPECT_EQ(std::stoi(m[1]), 2);
}

TEST_F(Run, AHostKilledMidProgramResumesFromItsJournal) {
  int port = 0;
  // Slow enough to kill the host mid-program: the 15 min program at 200x is about 4.5 s.
  auto sim = serve({"--modbus", "tcp://127.0.0.1:0", "--time-scale", "200"}, "modbus-tcp", port);
  {
    Background host(command({"run", plan().string(), "--machine", kMachine, "--transport",
                             "modbus-tcp://127.0.0.1:" + std::to_string(port), "--job", (dir_ / "job").string(), "--yes"}),
                    dir_, "host");
    // Once it streams (its status line says RUNNING; its journal exists), a little more, then kill it.
    wait_until_streaming(dir_ / "host.err");
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    ASSERT_TRUE(host.alive()) << "the host finished before it could be killed";
    ::kill(host.pid, SIGKILL);
    host.wait_exit(2);
  }
  EXPECT_EQ(run({"run", "--resume", (dir_ / "job").string(), "--yes"}), 0) << slurp(dir_ / "run.err");
  expect_exactly_once(*sim);
  EXPECT_NE(slurp(dir_ / "run.err").find("resuming: the controller executed through line"), std::string::npos);
}

TEST_F(Run, CtrlCHoldsTheFeedAndWithoutAnOperatorAborts) {
  int port = 0;
  auto sim = serve({"--modbus", "tcp://127.0.0.1:0", "--time-scale", "200"}, "modbus-tcp", port, false);
  Background host(command({"run", plan().string(), "--machine", kMachine, "--transport",
                           "modbus-tcp://127.0.0.1:" + std::to_string(port), "--job", (dir_ / "job").string(), "--yes"}),
                  dir_, "host");
  // Once it streams (its status line says RUNNING), Ctrl-C.
  wait_until_streaming(dir_ / "host.err");
  ASSERT_TRUE(host.alive());
  ::kill(host.pid, SIGINT);
  host.wait_exit(10);
  EXPECT_FALSE(host.alive());
  // No terminal to ask: the hold becomes an abort, said as such.
  const std::string out = slurp(dir_ / "host.out"), err = slurp(dir_ / "host.err");
  EXPECT_NE(err.find("feed hold (Ctrl-C)"), std::string::npos) << err;
  EXPECT_NE(out.find("STOPPED after"), std::string::npos) << out;
  EXPECT_NE(out.find("the program was aborted"), std::string::npos) << out;
  // The controller stopped where it was: fewer lines than the program.
  const std::string log = slurp(dir_ / "lines.ngc.tmp"), program = slurp(dir_ / "job" / "program.ngc");
  EXPECT_LT(log.size(), program.size());
}

// A hold at the machine (an operator pressed feed hold there) is not the host's to lift: the
// host waits, and says so every few seconds in its log and on its status line.
TEST_F(Run, AFeedHoldAtTheMachineIsWaitedOnOutLoud) {
  int port = 0;
  auto sim = serve({"--modbus", "tcp://127.0.0.1:0", "--time-scale", "200", "--hold-at-line", "200"}, "modbus-tcp", port,
                   false);
  Background host(command({"run", plan().string(), "--machine", kMachine, "--transport",
                           "modbus-tcp://127.0.0.1:" + std::to_string(port), "--job", (dir_ / "job").string(), "--yes"}),
                  dir_, "host");
  auto count = [](const std::string& text, const std::string& what) {
    std::size_t n = 0;
    for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
    return n;
  };
  const std::string note = "waiting: the controller is in FEED_HOLD, held at the machine after line 199";
  // Two notes 5 s apart (the documented period), within 30 s of streaming also in the
  // sanitizer build (the hold comes within the first second of streaming, which the
  // status line may never catch RUNNING in).
  wait_until_streaming(dir_ / "host.err", "FEED_HOLD");
  for (int i = 0; i < 600 && count(slurp(dir_ / "host.err"), note) < 2; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  const std::string err = slurp(dir_ / "host.err");
  EXPECT_GE(count(err, note), 2u) << err.substr(0, 3000);
  EXPECT_NE(err.find("FEED_HOLD"), std::string::npos) << err.substr(0, 3000);
  EXPECT_NE(err.find("waiting: feed hold: cycle start (RESUME)"), std::string::npos) << err.substr(0, 3000);
  EXPECT_TRUE(host.alive()) << "the host gave up on a hold that is the machine's to lift";
  // The controller ran nothing past the hold (its line log may lag behind, never run ahead).
  EXPECT_LE(count(slurp(dir_ / "lines.ngc.tmp"), "\n"), 199u);
}

TEST_F(Run, ASetupChangeStopsForTheOperatorAndGoesOnWhenAcknowledged) {
  // The flanged hub's best plan mills from below, then from above: the part is turned over
  // by hand in between (manual_refixture), a program stop with the operator's message.
  const fs::path plan_dir = plan().parent_path();
  std::vector<std::string> args = {"sim", "serve", "--machine", kMachine, "--stock", (plan_dir / "plan.json").string(),
                                   "--exit-when-done", "--line-log", (dir_ / "lines.ngc").string(), "--modbus",
                                   "tcp://127.0.0.1:0", "--time-scale", "0"};
  Background sim(command(args), dir_, "sim");
  int port = 0;
  for (int i = 0; i < kStartupPolls && !port; ++i) {
    std::smatch m;
    const std::string out = slurp(dir_ / "sim.out");
    if (std::regex_search(out, m, std::regex("listening modbus-tcp 127\\.0\\.0\\.1:([0-9]+)"))) port = std::stoi(m[1]);
    if (!port) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ASSERT_GT(port, 0);
  EXPECT_EQ(run({"run", (plan_dir / "plan.json").string(), "--machine", kMachine, "--transport",
                 "modbus-tcp://127.0.0.1:" + std::to_string(port), "--job", (dir_ / "job").string(), "--yes"}),
            0)
      << slurp(dir_ / "run.err");
  const std::string err = slurp(dir_ / "run.err");
  EXPECT_NE(err.find("program stop after line"), std::string::npos) << err;
  expect_exactly_once(sim);
}

TEST_F(Run, AResumeIntoAnotherProgramIsRefused) {
  int port = 0;
  auto sim = serve({"--modbus", "tcp://127.0.0.1:0", "--time-scale", "0"}, "modbus-tcp", port, false);
  const std::string uri = "modbus-tcp://127.0.0.1:" + std::to_string(port);
  // A small other program completes first; then a resume of the plan's job must refuse.
  std::ofstream(dir_ / "other.ngc") << "G21 G90\nG54\nG0 X10 Y10 Z50\nM2\n";
  ASSERT_EQ(run({"run", (dir_ / "other.ngc").string(), "--machine", kMachine, "--transport", uri, "--job",
                 (dir_ / "other-job").string(), "--yes"}),
            0)
      << slurp(dir_ / "run.err");
  fs::create_directories(dir_ / "job");
  // A journal of the plan's program, as a killed host would have left it.
  ASSERT_EQ(run({"run", plan().string(), "--machine", kMachine, "--transport", "modbus-tcp://127.0.0.1:1", "--job",
                 (dir_ / "job").string(), "--yes"}),
            6)
      << "nothing listens on port 1: unreachable";
  EXPECT_EQ(run({"run", "--resume", (dir_ / "job").string(), "--transport", uri, "--yes"}), 3);
  EXPECT_NE(slurp(dir_ / "run.err").find("refusing to resume into another program"), std::string::npos)
      << slurp(dir_ / "run.err");
}

TEST_F(Run, ModbusRtuOverASocatPtyPair) {
  ASSERT_EQ(std::system("command -v socat >/dev/null"), 0) << "socat is missing: run scripts/setup";
  Background socat("socat -d -d pty,raw,echo=0 pty,raw,echo=0", dir_, "socat");
  std::vector<std::string> ptys;
  for (int i = 0; i < kStartupPolls && ptys.size() < 2; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    ptys.clear();
    const std::string err = slurp(dir_ / "socat.err");
    const std::regex pts("PTY is (/dev/pts/[0-9]+)");
    for (auto it = std::sregex_iterator(err.begin(), err.end(), pts); it != std::sregex_iterator(); ++it) ptys.push_back((*it)[1]);
  }
  ASSERT_EQ(ptys.size(), 2u) << slurp(dir_ / "socat.err");
  std::vector<std::string> args = {"sim", "serve", "--machine", kMachine, "--stock", plan().string(), "--exit-when-done",
                                   "--line-log", (dir_ / "lines.ngc").string(), "--modbus-rtu", ptys[0], "--baud", "115200",
                                   "--parity", "N", "--time-scale", "0"};
  Background sim(command(args), dir_, "sim");
  for (int i = 0; i < kStartupPolls && slurp(dir_ / "sim.out").find("ready") == std::string::npos; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_EQ(run({"run", plan().string(), "--machine", kMachine, "--transport",
                 "modbus-rtu://" + ptys[1] + "?baud=115200&parity=N&unit=1", "--job", (dir_ / "job").string(), "--yes"}),
            0)
      << slurp(dir_ / "run.err") << slurp(dir_ / "sim.err");
  expect_exactly_once(sim);
}

// The fins, a part the fixture's plan does not share: dry-run plans it itself.
TEST_F(Run, DryRunComparesAsBuiltWithAsPlanned) {
  const std::string cmd = command({"dry-run", (kSource / "examples/parts/fins.stl").string(), "--machine", kMachine,
                                   "--voxel", "0.5", "-o", (dir_ / "out").string()}) +
                          " >" + quote((dir_ / "dry.out").string()) + " 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << slurp(dir_ / "dry.out");
  const std::string out = slurp(dir_ / "dry.out");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(out, m, std::regex("as built +([0-9.]+) mm³ \\(planned ([0-9.]+) mm³\\): ([0-9.]+) mm³ beyond the "
                                                   "plan, ([0-9.]+) mm³ of it missing")))
      << out;
  const double planned = std::stod(m[2]), extra = std::stod(m[3]), missing = std::stod(m[4]);
  // The replay bounds of docs/export.md: overfill within 10 %, left empty within 2 %.
  EXPECT_LE(extra, 0.10 * planned);
  EXPECT_LE(missing, 0.02 * planned);
  EXPECT_TRUE(slurp(dir_ / "out" / "plan-1" / "executed-lines.ngc") == slurp(dir_ / "out" / "plan-1" / "job" / "program.ngc"));
  // The voxels are judged within their band; the program the controller ran, against the
  // STL, within the tolerance.
  EXPECT_NE(out.find("\non voxels   "), std::string::npos) << out;
  EXPECT_TRUE(std::regex_search(out, std::regex("\nvs STL      excess [0-9.]+ mm.*; [0-9.]+ % of the surface within 0.5 mm: "
                                                "within tolerance\n")))
      << out;
}

}  // namespace

namespace {

// A `sim serve` on a given port (0: any), with its own line log and the stock of the plan
// `stock` (none when empty); returns the port.
int start_sim(std::unique_ptr<Background>& sim, const fs::path& dir, const std::string& name, int port, const std::string& time_scale,
              const std::string& stock) {
  std::vector<std::string> args = {"sim", "serve", "--machine", kMachine, "--line-log", (dir / (name + ".ngc")).string(),
                                   "--modbus", "tcp://127.0.0.1:" + std::to_string(port), "--time-scale", time_scale,
                                   "--exit-when-done"};
  if (!stock.empty()) args.insert(args.end(), {"--stock", stock});
  sim = std::make_unique<Background>(command(args), dir, name);
  for (int i = 0; i < kStartupPolls; ++i) {
    std::smatch m;
    const std::string out = slurp(dir / (name + ".out"));
    if (std::regex_search(out, m, std::regex("listening modbus-tcp 127\\.0\\.0\\.1:([0-9]+)")) && out.find("ready") != std::string::npos)
      return std::stoi(m[1]);
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ADD_FAILURE() << slurp(dir / (name + ".err"));
  return 0;
}

// The last executed line the journal recorded.
std::uint32_t journal_executed(const fs::path& journal) {
  const std::string j = slurp(journal);
  const auto at = j.rfind("\"executed_line\":");
  return at == std::string::npos ? 0 : std::uint32_t(std::stoul(j.substr(at + 16)));
}

// A controller power cycle mid-program: the simulator killed (SIGKILL) at about line 1500
// and a new one started on the same port, with no program and no safe point. The host
// waits for it (beyond the transport's reconnect attempts), stops at the first status of
// the new controller, says what ran, what may have, and what to do; `run --resume --from-line` then runs the rest once.
TEST_F(Run, AControllerPowerLossStopsTheHostWhichSaysWhatRanAndResumesFromTheSafePoint) {
  std::unique_ptr<Background> first, second;
  const int port = start_sim(first, dir_, "sim1", 0, "200", plan().string());
  ASSERT_GT(port, 0);
  const std::string uri = "modbus-tcp://127.0.0.1:" + std::to_string(port);
  Background host(command({"run", plan().string(), "--machine", kMachine, "--transport", uri, "--job", (dir_ / "job").string(), "--yes"}),
                  dir_, "host");
  for (int i = 0; i < 1200 && journal_executed(dir_ / "job" / "journal.jsonl") < 1500; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  ASSERT_GE(journal_executed(dir_ / "job" / "journal.jsonl"), 1500u) << slurp(dir_ / "host.err").substr(0, 2000);
  ::kill(first->pid, SIGKILL);
  first->wait_exit(5);
  // A power cycle outlasts the transport's reconnect attempts (about 11 s): the host says
  // it waits for the controller, and the controller comes back only after that.
  for (int i = 0; i < 1200 && slurp(dir_ / "host.err").find("waiting for it to come back") == std::string::npos; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  ASSERT_NE(slurp(dir_ / "host.err").find("the controller does not answer"), std::string::npos) << slurp(dir_ / "host.err");
  ASSERT_TRUE(host.alive()) << slurp(dir_ / "host.err").substr(0, 2000);
  // The new simulator starts without stock: what the first one milled died with it (a real
  // machine keeps its part); the subject here is the host's journal and the restart.
  ASSERT_GT(start_sim(second, dir_, "sim2", port, "0", ""), 0);
  // The documented bound (docs/drivers.md): the first status read once the controller
  // answers again, at most one reconnect backoff step (2 s) after it is back.
  const auto back = std::chrono::steady_clock::now();
  host.wait_exit(10);
  EXPECT_FALSE(host.alive()) << "the host did not stop: " << slurp(dir_ / "host.err").substr(0, 2000);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - back).count(), 5.0);
  int status = 0;
  (void)::waitpid(host.pid, &status, WNOHANG);  // not our child (started by the shell): read its report instead
  const std::string out = slurp(dir_ / "host.out");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(out, m, std::regex(R"(controller lost the program: .*\n  executed    lines 1\.\.(\d+), as the controller reported them\n  uncertain   lines (\d+)\.\.(\d+) )")))
      << out << slurp(dir_ / "host.err").substr(0, 2000);
  const std::uint32_t executed = std::stoul(m[1]), accepted = std::stoul(m[3]);
  EXPECT_EQ(std::stoul(m[2]), executed + 1);
  ASSERT_TRUE(std::regex_search(out, m, std::regex(R"(hybridctl run --resume (\S+) --from-line (\d+))"))) << out;
  EXPECT_EQ(m[1], (dir_ / "job").string());
  const std::uint32_t from = std::stoul(m[2]);
  EXPECT_EQ(from, executed + 1);
  EXPECT_NE(slurp(dir_ / "job" / "journal.jsonl").find("\"lost\""), std::string::npos);
  // The first controller ran no line past the uncertain span (its log is what it flushed).
  const std::string program = slurp(dir_ / "job" / "program.ngc"), log1 = slurp(dir_ / "sim1.ngc.tmp");
  EXPECT_LE(std::count(log1.begin(), log1.end(), '\n'), long(accepted));
  EXPECT_EQ(program.compare(0, log1.size(), log1), 0) << "the first controller's log is a prefix of the program";

  // Lines before the safe point would run twice; lines after the uncertain span were never sent.
  EXPECT_EQ(run({"run", "--resume", (dir_ / "job").string(), "--from-line", std::to_string(executed), "--yes"}), 3);
  EXPECT_NE(slurp(dir_ / "run.err").find("not a safe point"), std::string::npos) << slurp(dir_ / "run.err");
  EXPECT_EQ(run({"run", "--resume", (dir_ / "job").string(), "--from-line", std::to_string(accepted + 2), "--yes"}), 3);
  EXPECT_EQ(run({"run", "--resume", (dir_ / "job").string(), "--from-line", "99999999", "--yes"}), 3);
  ASSERT_EQ(run({"run", "--resume", (dir_ / "job").string(), "--from-line", std::to_string(from), "--yes"}), 0)
      << slurp(dir_ / "run.err").substr(0, 3000);
  second->wait_exit(10);
  // The new boot ran the restart (its preamble, then lines N..end), each line once.
  const fs::path restart = dir_ / "job" / ("program-from-line-" + std::to_string(from) + ".ngc");
  const std::string log2 = slurp(dir_ / "sim2.ngc"), restart_text = slurp(restart);
  EXPECT_TRUE(log2 == restart_text) << log2.size() << " vs " << restart_text.size();
  std::size_t at = 0;
  for (std::uint32_t l = 1; l < from; ++l) at = program.find('\n', at) + 1;
  const std::string rest = program.substr(at);
  ASSERT_GE(log2.size(), rest.size());
  EXPECT_TRUE(log2.compare(log2.size() - rest.size(), rest.size(), rest) == 0) << "the new boot's log ends with lines N..end";
  EXPECT_EQ(restart_text.rfind("(restart at line " + std::to_string(from) + ":", 0), 0u);
}

}  // namespace
