#pragma once
// What `hybridctl run` does, shared with `hybridctl dry-run`.

#include <string>

namespace hybridctl::cli {

struct RunRequest {
  std::string input;      // plan.json or its directory, or a program
  std::string machine;
  std::string transport;  // URI
  int rank = 1;
  std::string job;        // job directory
  std::string resume;     // job directory to resume
  unsigned from_line = 0; // with resume: restart the program there (the controller lost it)
  bool yes = false;
};

int run_job(const RunRequest& request);

}  // namespace hybridctl::cli
