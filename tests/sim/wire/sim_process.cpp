#include "sim_process.hpp"

#include <gtest/gtest.h>

#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>

#include <fcntl.h>
#include <poll.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "../../sanitizer_report.hpp"

extern char** environ;

namespace hybridctl::test {
namespace {

using Clock = std::chrono::steady_clock;

struct Spawned {
  pid_t pid = -1;
  int out_fd = -1;  // read end of the stdout (and stderr, unless redirected) pipe
};

// posix_spawn with stdin from /dev/null, stdout to a pipe, stderr to the pipe or a file.
Spawned spawn(const std::vector<std::string>& argv, const std::string& stderr_path) {
  int pipe_fds[2];
  if (::pipe2(pipe_fds, O_CLOEXEC) != 0) throw std::runtime_error("pipe: " + std::string(std::strerror(errno)));
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], 1);
  if (stderr_path.empty()) {
    posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], 2);
  } else {
    posix_spawn_file_actions_addopen(&actions, 2, stderr_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  }
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  Spawned s;
  const int rc = ::posix_spawnp(&s.pid, args[0], &actions, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  ::close(pipe_fds[1]);
  if (rc != 0) {
    ::close(pipe_fds[0]);
    throw std::runtime_error("cannot start " + argv[0] + ": " + std::strerror(rc));
  }
  s.out_fd = pipe_fds[0];
  return s;
}

// Reads what is available (waiting at most `wait` for the first bytes); false at EOF.
bool read_some(int fd, std::string& into, std::chrono::milliseconds wait) {
  pollfd p{fd, POLLIN, 0};
  if (::poll(&p, 1, static_cast<int>(wait.count())) <= 0) return true;
  char buffer[4096];
  const ssize_t n = ::read(fd, buffer, sizeof buffer);
  if (n <= 0) return false;
  into.append(buffer, static_cast<std::size_t>(n));
  return true;
}

int decode_status(int status) {
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return -1;
}

// Waits for pid up to `timeout`; the decoded status or -1.
int wait_for(pid_t pid, std::chrono::milliseconds timeout) {
  const auto end = Clock::now() + timeout;
  for (;;) {
    int status = 0;
    const pid_t r = ::waitpid(pid, &status, WNOHANG);
    if (r == pid) return decode_status(status);
    if (r < 0) return -1;
    if (Clock::now() >= end) return -1;
    std::this_thread::sleep_for(5ms);
  }
}

// SIGTERM, then SIGKILL after `grace`; the decoded status.
int terminate(pid_t pid, std::chrono::milliseconds grace) {
  ::kill(pid, SIGTERM);
  int code = wait_for(pid, grace);
  if (code == -1) {
    ::kill(pid, SIGKILL);
    int status = 0;
    ::waitpid(pid, &status, 0);
    code = decode_status(status);
  }
  return code;
}

// A sanitizer report in a child's output fails the test (the sanitizer build): the
// processes ended by SIGTERM at a test's end would otherwise go unread.
void expect_no_sanitizer_report(const std::string& what, const std::string& output) {
  const std::string report = sanitizer_report(output);
  if (!report.empty()) ADD_FAILURE() << "sanitizer report from " << what << ":\n" << report;
}

}  // namespace

std::string example_machine() { return std::string(HYBRIDCTL_SOURCE_DIR) + "/examples/machines/hybrid-3axis.yaml"; }

std::string find_program(const std::string& program) {
  auto executable = [](const std::string& path) {
    struct stat st {};
    return ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode) && ::access(path.c_str(), X_OK) == 0;
  };
  if (program.find('/') != std::string::npos) return executable(program) ? program : std::string();
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "/usr/local/bin:/usr/bin:/bin");
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    const std::string candidate = (dir.empty() ? "." : dir) + "/" + program;
    if (executable(candidate)) return candidate;
  }
  return {};
}

std::string require_program(const std::string& program) {
  const std::string path = find_program(program);
  if (path.empty()) {
    ADD_FAILURE() << "the peer '" << program
                  << "' is missing: this test needs it (run scripts/setup, which installs mbpoll, socat, "
                     "python3-pymodbus and python3-can)";
  }
  return path;
}

PeerResult run_peer(const std::vector<std::string>& argv, std::chrono::milliseconds timeout) {
  PeerResult result;
  Spawned s;
  try {
    s = spawn(argv, "");
  } catch (const std::exception& e) {
    result.output = e.what();
    return result;
  }
  const auto end = Clock::now() + timeout;
  while (Clock::now() < end) {
    if (!read_some(s.out_fd, result.output, 50ms)) break;
  }
  if (Clock::now() >= end) {
    result.timed_out = true;
    ::kill(s.pid, SIGKILL);
  }
  int status = 0;
  ::waitpid(s.pid, &status, 0);
  ::close(s.out_fd);
  result.exit_code = decode_status(status);
  expect_no_sanitizer_report(argv[0], result.output);
  return result;
}

// ---------------------------------------------------------------- BackgroundProcess

BackgroundProcess::BackgroundProcess(const std::vector<std::string>& argv) {
  const Spawned s = spawn(argv, "");
  pid_ = s.pid;
  out_fd_ = s.out_fd;
}

BackgroundProcess::~BackgroundProcess() {
  if (pid_ > 0) stop();
  if (out_fd_ >= 0) ::close(out_fd_);
}

void BackgroundProcess::read_available(std::chrono::milliseconds wait) { read_some(out_fd_, output_, wait); }

bool BackgroundProcess::wait_output(bool (*predicate)(const std::string&), std::chrono::milliseconds timeout) {
  const auto end = Clock::now() + timeout;
  while (!predicate(output_)) {
    if (Clock::now() >= end) return false;
    if (!read_some(out_fd_, output_, 50ms) && !predicate(output_)) return false;
  }
  return true;
}

int BackgroundProcess::stop() {
  if (pid_ <= 0) return -1;
  const int code = terminate(pid_, 5000ms);
  pid_ = -1;
  for (std::size_t before = output_.size() + 1; output_.size() != before;) {
    before = output_.size();
    read_available(0ms);
  }
  expect_no_sanitizer_report("a background process", output_);
  return code;
}

// ---------------------------------------------------------------- SimProcess

SimProcess::SimProcess(std::vector<std::string> args) {
  char err_template[] = "/tmp/hybridctl-sim-stderr-XXXXXX";
  const int err_fd = ::mkstemp(err_template);
  if (err_fd >= 0) ::close(err_fd);
  err_path_ = err_template;
  std::vector<std::string> argv = {HYBRIDCTL_EXE, "sim", "serve"};
  argv.insert(argv.end(), args.begin(), args.end());
  const Spawned s = spawn(argv, err_path_);
  pid_ = s.pid;
  out_fd_ = s.out_fd;
  const auto end = Clock::now() + 20s;
  while (stdout_.find("ready\n") == std::string::npos) {
    int status = 0;
    if (::waitpid(pid_, &status, WNOHANG) == pid_) {
      pid_ = -1;
      read_stdout(0ms);
      throw std::runtime_error("hybridctl sim serve exited (status " + std::to_string(decode_status(status)) +
                               ") before it was ready; stdout:\n" + stdout_ + "stderr:\n" + errors());
    }
    if (Clock::now() >= end) {
      stop();
      throw std::runtime_error("hybridctl sim serve printed no 'ready' line in 20 s; stdout:\n" + stdout_ +
                               "stderr:\n" + errors());
    }
    read_stdout(50ms);
  }
  std::istringstream lines(stdout_);
  std::string line;
  while (std::getline(lines, line)) {
    // "listening modbus-tcp 127.0.0.1:1502"
    std::istringstream words(line);
    std::string word, transport, address;
    if (words >> word >> transport >> address && word == "listening") {
      const auto colon = address.rfind(':');
      if (colon != std::string::npos) ports_[transport] = std::atoi(address.c_str() + colon + 1);
    }
  }
}

SimProcess::~SimProcess() {
  if (pid_ > 0) stop();
  if (out_fd_ >= 0) ::close(out_fd_);
  ::unlink(err_path_.c_str());
}

void SimProcess::read_stdout(std::chrono::milliseconds wait) {
  if (out_fd_ >= 0) read_some(out_fd_, stdout_, wait);
}

int SimProcess::port(std::string_view transport) const {
  const auto it = ports_.find(transport);
  return it == ports_.end() ? -1 : it->second;
}

int SimProcess::stop() {
  if (pid_ <= 0) return -1;
  const int code = terminate(pid_, 15000ms);
  pid_ = -1;
  while (out_fd_ >= 0) {
    const std::size_t before = stdout_.size();
    read_stdout(0ms);
    if (stdout_.size() == before) break;
  }
  expect_no_sanitizer_report("hybridctl sim serve", errors());
  return code;
}

int SimProcess::wait(std::chrono::milliseconds timeout) {
  if (pid_ <= 0) return -1;
  const auto end = Clock::now() + timeout;
  for (;;) {
    int status = 0;
    if (::waitpid(pid_, &status, WNOHANG) == pid_) {
      pid_ = -1;
      read_stdout(0ms);
      expect_no_sanitizer_report("hybridctl sim serve", errors());
      return decode_status(status);
    }
    if (Clock::now() >= end) return -1;
    read_stdout(20ms);
  }
}

std::string SimProcess::errors() const {
  std::ifstream in(err_path_);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

PeerResult SimProcess::run_to_exit(std::vector<std::string> args, std::chrono::milliseconds timeout) {
  std::vector<std::string> argv = {HYBRIDCTL_EXE, "sim", "serve"};
  argv.insert(argv.end(), args.begin(), args.end());
  return run_peer(argv, timeout);
}

}  // namespace hybridctl::test
