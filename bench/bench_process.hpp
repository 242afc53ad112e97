#pragma once
// What the wire benchmarks share: `hybridctl sim serve` started as a separate process on a
// free loopback port (waiting for its "ready" line), and pinning processes to one CPU (on
// these 2-vCPU machines unpinned loopback round trips swing 4x; ../shared/PEERS.md).
//
//   bench::ChildProcess sim = bench::start_simulator({"--modbus", "tcp://127.0.0.1:0"}, "modbus-tcp");
//   connect to 127.0.0.1:sim.port ...   // SIGTERM and reaped when `sim` goes out of scope
//
// Header-only and included by the bench programs alone (HYBRIDCTL_SOURCE_DIR and
// HYBRIDCTL_EXE come from bench/CMakeLists.txt).

#include <poll.h>
#include <sched.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>


extern char** environ;

namespace hybridctl::bench {

inline constexpr int kBenchCpu = 0;

/// Pins `pid` (0: the calling thread) to kBenchCpu.
inline void pin_to_cpu(pid_t pid) {
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(kBenchCpu, &set);
  if (sched_setaffinity(pid, sizeof set, &set) != 0) std::perror("sched_setaffinity");
}

/// A child process: SIGTERM and reaped at destruction.
struct ChildProcess {
  pid_t pid = -1;
  int port = 0;

  ChildProcess() = default;
  ChildProcess(ChildProcess&& o) noexcept : pid(std::exchange(o.pid, -1)), port(o.port) {}
  ChildProcess& operator=(ChildProcess&& o) noexcept {
    std::swap(pid, o.pid);
    port = o.port;
    return *this;
  }
  ~ChildProcess() {
    if (pid > 0) {
      ::kill(pid, SIGTERM);
      ::waitpid(pid, nullptr, 0);
    }
  }
};

/// `hybridctl sim serve --machine examples/machines/hybrid-3axis.yaml --time-scale 0
/// --heartbeat-timeout 0 ARGS...`, pinned; `endpoint` names the "listening ENDPOINT
/// 127.0.0.1:PORT" line the port is read from ("modbus-tcp", "socketcand").
inline ChildProcess start_simulator(const std::vector<std::string>& extra_args, const std::string& endpoint) {
  int fds[2];
  if (::pipe(fds) != 0) throw std::runtime_error("pipe");
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, fds[1], 1);
  posix_spawn_file_actions_addclose(&actions, fds[0]);
  std::vector<std::string> args = {HYBRIDCTL_EXE, "sim",          "serve", "--machine",
                                   std::string(HYBRIDCTL_SOURCE_DIR) + "/examples/machines/hybrid-3axis.yaml",
                                   "--time-scale",  "0",            "--heartbeat-timeout", "0"};
  args.insert(args.end(), extra_args.begin(), extra_args.end());
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  ChildProcess child;
  if (posix_spawn(&child.pid, argv[0], &actions, nullptr, argv.data(), environ) != 0)
    throw std::runtime_error("cannot start " + args[0]);
  posix_spawn_file_actions_destroy(&actions);
  ::close(fds[1]);
  pin_to_cpu(child.pid);
  std::string out;
  char buffer[256];
  while (out.find("ready\n") == std::string::npos) {
    pollfd p{fds[0], POLLIN, 0};
    if (::poll(&p, 1, 20000) <= 0) throw std::runtime_error("the simulator printed no 'ready' line");
    const ssize_t n = ::read(fds[0], buffer, sizeof buffer);
    if (n <= 0) throw std::runtime_error("the simulator exited: " + out);
    out.append(buffer, static_cast<std::size_t>(n));
  }
  ::close(fds[0]);
  const std::string key = "listening " + endpoint + " 127.0.0.1:";
  const auto at = out.find(key);
  if (at == std::string::npos) throw std::runtime_error("the simulator printed no '" + key + "' line: " + out);
  child.port = std::stoi(out.substr(at + key.size()));
  return child;
}

}  // namespace hybridctl::bench
