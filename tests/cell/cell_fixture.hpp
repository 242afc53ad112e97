#pragma once
// What the cell's tests share: a PostgreSQL server of the test's own on 127.0.0.1
// (postgres_server.hpp), `hybridctl cell` run as separate processes, a box part, and
// queries of the test's own.

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "../cli/shell.hpp"
#include "cell/database.hpp"
#include "postgres_server.hpp"

namespace hybridctl::cell::cell_testing {

namespace fs = std::filesystem;
using cli_testing::quote;
using cli_testing::run_shell;
using cli_testing::slurp;

inline const fs::path kSource = HYBRIDCTL_SOURCE_DIR;

// A closed box of sx x sy x sz mm as a binary STL, outward facets: a part any mill makes
// from the plate in well under a second of planning at 2 mm voxels.
inline void write_box(const fs::path& path, float sx, float sy, float sz) {
  auto vertex = [&](int i) { return std::array<float, 3>{i & 4 ? sx : 0.f, i & 2 ? sy : 0.f, i & 1 ? sz : 0.f}; };
  const int quads[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1}, {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
  std::ofstream out(path, std::ios::binary);
  const std::string header(80, '\0');
  out.write(header.data(), 80);
  const std::uint32_t count = 12;
  out.write(reinterpret_cast<const char*>(&count), 4);
  for (const auto& q : quads)
    for (const auto& tri : {std::array<int, 3>{q[0], q[1], q[2]}, std::array<int, 3>{q[0], q[2], q[3]}}) {
      const float normal[3] = {0, 0, 0};
      out.write(reinterpret_cast<const char*>(normal), 12);
      for (int v : tri) out.write(reinterpret_cast<const char*>(vertex(v).data()), 12);
      const char attribute[2] = {0, 0};
      out.write(attribute, 2);
    }
}

// The `hybridctl plan` processes whose parent is `parent` (a worker's planning child).
// Only this worker's: other cell tests may be planning beside this one.
inline std::vector<pid_t> plan_children_of(pid_t parent) {
  std::vector<pid_t> children;
  for (const fs::directory_entry& e : fs::directory_iterator("/proc")) {
    const std::string name = e.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    const std::string stat = slurp(e.path() / "stat");  // "pid (comm) state ppid ..."
    const auto after_comm = stat.rfind(')');
    if (after_comm == std::string::npos) continue;
    std::istringstream rest(stat.substr(after_comm + 1));
    char state = 0;
    pid_t ppid = 0;
    rest >> state >> ppid;
    const std::string cmdline = slurp(e.path() / "cmdline");  // arguments separated by NULs
    if (ppid == parent && cmdline.find(std::string("\0plan\0", 6)) != std::string::npos) children.push_back(std::stoi(name));
  }
  return children;
}

// Whether the process runs (a zombie no longer does: it only waits to be reaped).
inline bool running(pid_t pid) {
  const std::string stat = slurp(fs::path("/proc") / std::to_string(pid) / "stat");
  const auto after_comm = stat.rfind(')');
  return after_comm != std::string::npos && after_comm + 2 < stat.size() && stat[after_comm + 2] != 'Z';
}

// A process of the test's (a plan worker), its output in files.
struct Process {
  pid_t pid = -1;
  Process(const std::string& cmd, const fs::path& out) {
    pid = fork();
    if (pid == 0) {
      // exec: the pid is the command's own, so that a signal sent to it reaches it.
      execl("/bin/sh", "sh", "-c", ("exec " + cmd + " >" + quote(out.string()) + " 2>&1 </dev/null").c_str(), static_cast<char*>(nullptr));
      _exit(127);
    }
  }
  // The exit code, waiting at most `seconds`; -1 when it is still running.
  int wait(double seconds) {
    for (int i = 0; i < int(seconds * 20); ++i) {
      int status = 0;
      if (waitpid(pid, &status, WNOHANG) == pid) {
        pid = -1;
        return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    return -1;
  }
  ~Process() {
    if (pid > 0) {
      kill(pid, SIGKILL);
      waitpid(pid, nullptr, 0);
    }
  }
};

class CellTest : public cli_testing::DirectoryTest {
 protected:
  explicit CellTest(std::string prefix) : DirectoryTest(std::move(prefix)) {}
  void SetUp() override {
    DirectoryTest::SetUp();
    server_ = std::make_unique<testing::PostgresServer>();
    box_ = dir_ / "box.stl";
    write_box(box_, 20, 16, 10);
  }
  void TearDown() override {
    server_.reset();
    DirectoryTest::TearDown();
  }

  cli_testing::Outcome cell(const std::string& args) {
    return run_shell(quote(HYBRIDCTL_EXE) + " cell " + args + " --db " + quote(server_->uri()), dir_);
  }
  std::string worker_command(const std::string& args) const {
    return quote(HYBRIDCTL_EXE) + " cell plan-worker " + args + " --db " + quote(server_->uri());
  }
  // The cell made, with the bundled 3-axis machine registered as "mill".
  void init_with_a_machine() {
    ASSERT_EQ(cell("init").exit_code, 0);
    const auto added = cell("machines add mill --machine " + quote((kSource / "examples/machines/hybrid-3axis.yaml").string()));
    ASSERT_EQ(added.exit_code, 0) << added.err;
  }
  std::int64_t submit(const fs::path& part, const std::string& options = "--voxel 2") {
    const auto r = cell("submit " + quote(part.string()) + " --machine mill " + options);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return r.exit_code == 0 ? std::stoll(r.out) : 0;
  }
  // A query's single value, through our own connection.
  std::string value(const std::string& sql) {
    Database db(server_->uri());
    const Rows rows = db.exec("the test's query", sql);
    return rows.empty() ? "" : rows.text(0, 0);
  }
  // Waits until the query's value is `want`, at most `seconds`.
  bool becomes(const std::string& sql, const std::string& want, double seconds) {
    for (int i = 0; i < int(seconds * 10); ++i) {
      if (value(sql) == want) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    return false;
  }

  std::unique_ptr<testing::PostgresServer> server_;
  fs::path box_;
};

}  // namespace hybridctl::cell::cell_testing
