#pragma once
// `hybridctl run` at a terminal, shared with `hybridctl dry-run` and `cell machine-host`:
// the plan executor (drivers/executor.hpp) with its status line, prompts (--yes answers
// them), Ctrl-C as a feed hold, and the final report printed.

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace hybridctl::drivers {
struct RecordedJob;
struct JobResult;
}  // namespace hybridctl::drivers

namespace hybridctl::cli {

struct RunRequest {
  std::string input;      // plan.json or its directory, or a program
  std::string machine;    // empty: a plan's embedded machine
  bool machine_override = false;  // take `machine` even when it is not the plan's
  std::string transport;  // URI
  int rank = 1;
  std::string job;        // job directory
  std::string resume;     // job directory to resume
  unsigned from_line = 0; // with resume: restart the program there (the controller lost it)
  bool yes = false;
  double wait_for_controller = 120;  // s: a controller silent mid-program is waited for this long
};

// Returns the exit code: kSuccess, or kMachineStopped when the machine stopped first.
// `alarms`, when given, receives every alarm raised, in order, with its line.
int run_job(const RunRequest& request, std::vector<std::pair<std::string, std::uint32_t>>* alarms = nullptr);

// The same for a job the shop cell records (`cell machine-host`): status, prompts (`yes`
// answers them), Ctrl-C, the final report; returns how it ended. Throws as
// drivers::execute_recorded_job does.
drivers::JobResult run_recorded_job(const drivers::RecordedJob& job, bool yes);

// A yes-or-no question on the terminal; false without one (stdin not a terminal).
bool ask_at_terminal(const std::string& question);

}  // namespace hybridctl::cli
