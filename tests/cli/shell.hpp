#pragma once
// What the CLI tests share: running hybridctl (or any command) through the shell and
// reading back what it wrote.

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "../sanitizer_report.hpp"

namespace hybridctl::cli_testing {

struct Outcome {
  int exit_code = -1;
  std::string out, err;
};

inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// The directory of the running test, TMP/hybridctl-PREFIX-PID-TEST (not yet created).
inline std::filesystem::path test_directory(const std::string& prefix) {
  return std::filesystem::temp_directory_path() / ("hybridctl-" + prefix + "-" + std::to_string(::getpid()) + "-" +
                                                   ::testing::UnitTest::GetInstance()->current_test_info()->name());
}

// One argument for /bin/sh, single-quoted.
inline std::string quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// Runs `command` with its output in DIR/stdout and DIR/stderr and stdin from /dev/null; a
// sanitizer report on its stderr is a test failure.
inline Outcome run_shell(const std::string& command, const std::filesystem::path& dir) {
  const std::string cmd = command + " >" + quote((dir / "stdout").string()) + " 2>" + quote((dir / "stderr").string()) +
                          " </dev/null";
  const int status = std::system(cmd.c_str());
  Outcome r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  r.out = slurp(dir / "stdout");
  r.err = slurp(dir / "stderr");
  // In the sanitizer build a report fails the test even where a failure is the expected outcome.
  const std::string report = hybridctl::test::sanitizer_report(r.err);
  if (!report.empty()) ADD_FAILURE() << "sanitizer report from " << command << ":\n" << report;
  return r;
}

// A test with a fresh directory of its own (`dir_`), removed at its end, where the
// hybridctl it runs leaves its output.
class DirectoryTest : public ::testing::Test {
 protected:
  explicit DirectoryTest(std::string prefix) : prefix_(std::move(prefix)) {}
  void SetUp() override {
    dir_ = test_directory(prefix_);
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  // hybridctl ARGS (HYBRIDCTL_EXE), run in the shell.
  Outcome run_hybridctl(const std::vector<std::string>& args) {
    std::string cmd = quote(HYBRIDCTL_EXE);
    for (const auto& a : args) cmd += " " + quote(a);
    return run_shell(cmd, dir_);
  }

  std::filesystem::path dir_;

 private:
  std::string prefix_;
};

}  // namespace hybridctl::cli_testing
