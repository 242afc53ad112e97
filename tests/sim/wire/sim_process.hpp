#pragma once
// Test helpers for the simulator on the wire: `hybridctl sim serve` as a separate process
// (SimProcess) and the independent peers the tests talk to it with (run_peer: mbpoll,
// socat, /usr/bin/python3 with pymodbus or python-can).
//
//   SimProcess sim({"--machine", machine, "--modbus", "tcp://127.0.0.1:0"});
//   int port = sim.modbus_port();          // from its "listening modbus-tcp 127.0.0.1:PORT" line
//   PeerResult r = run_peer({"mbpoll", "-m", "tcp", "-p", std::to_string(port), ...});
//   int exit = sim.stop();                 // SIGTERM, then its exit status
//
// A missing peer is a failure (require_program), never a skip: scripts/setup installs
// them all.

#include <sys/types.h>

#include <chrono>
#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace hybridctl::test {

using namespace std::chrono_literals;

/// The example machine every wire test runs the controller for.
std::string example_machine();

/// Full path of `program` (searched on PATH unless it contains '/'); "" when missing.
std::string find_program(const std::string& program);

/// The path of `program`, or a gtest fatal failure naming the missing peer and how to get
/// it (call with ASSERT_NO_FATAL_FAILURE or from a test body; returns "" after failing).
std::string require_program(const std::string& program);

struct PeerResult {
  int exit_code = -1;       ///< exit status, 128 + signal when killed, -1 when it did not start
  bool timed_out = false;   ///< killed after the timeout
  std::string output;       ///< stdout and stderr together
};

/// Runs argv (argv[0] searched on PATH), stdin from /dev/null, output captured, killed
/// after `timeout`.
PeerResult run_peer(const std::vector<std::string>& argv, std::chrono::milliseconds timeout = 30s);

/// A process started in the background with its output captured (socat, a long-running
/// peer). Killed (SIGTERM, then SIGKILL) at destruction.
class BackgroundProcess {
 public:
  explicit BackgroundProcess(const std::vector<std::string>& argv);
  ~BackgroundProcess();
  BackgroundProcess(const BackgroundProcess&) = delete;
  BackgroundProcess& operator=(const BackgroundProcess&) = delete;

  pid_t pid() const { return pid_; }
  /// Reads output until `predicate(all output so far)` holds or the timeout passes.
  bool wait_output(bool (*predicate)(const std::string&), std::chrono::milliseconds timeout);
  const std::string& output() const { return output_; }
  /// SIGTERM and wait; the exit status (128 + signal when killed).
  int stop();

 private:
  void read_available(std::chrono::milliseconds wait);
  pid_t pid_ = -1;
  int out_fd_ = -1;
  std::string output_;
};

/// `hybridctl sim serve ARGS...` in the background.
class SimProcess {
 public:
  /// Starts it and waits for its "ready" line; throws std::runtime_error with what it
  /// printed if it exits first or stays silent for 20 s.
  explicit SimProcess(std::vector<std::string> args);
  ~SimProcess();
  SimProcess(const SimProcess&) = delete;
  SimProcess& operator=(const SimProcess&) = delete;

  /// The port of "listening TRANSPORT HOST:PORT" (transport "modbus-tcp", "socketcand");
  /// -1 when it printed none.
  int port(std::string_view transport) const;
  int modbus_port() const { return port("modbus-tcp"); }
  int socketcand_port() const { return port("socketcand"); }

  /// SIGTERM and wait (SIGKILL after 15 s); the exit status (128 + signal when killed).
  int stop();
  /// Waits for it to exit by itself (--exit-when-done); its exit status, or -1 on timeout.
  int wait(std::chrono::milliseconds timeout);
  bool running() const { return pid_ > 0; }
  pid_t pid() const { return pid_; }

  const std::string& output() const { return stdout_; }  ///< stdout so far
  std::string errors() const;                              ///< stderr so far

  /// Starts it expecting failure: runs to completion and returns exit status and output.
  static PeerResult run_to_exit(std::vector<std::string> args, std::chrono::milliseconds timeout = 30s);

 private:
  void read_stdout(std::chrono::milliseconds wait);
  pid_t pid_ = -1;
  int out_fd_ = -1;
  std::string err_path_;
  std::string stdout_;
  std::map<std::string, int, std::less<>> ports_;
};

}  // namespace hybridctl::test
