#pragma once
// `hybridctl cell plan-worker` (docs/cell.md, "Plan workers"): takes the cell's jobs one at
// a time, plans each by running this same hybridctl's `plan ... --report` as a child
// process in a directory of its own (so a job that crashes or runs out of memory takes
// only itself down), renews the job's lease while the child plans, and stores the plan
// directory's files and the outcome in the database.

#include <string>

namespace hybridctl::cli {

struct PlanWorkerOptions {
  std::string db;            // libpq URI or connection string
  std::string name;          // how the worker signs its leases; empty: host:pid
  double lease_s = 30;       // a lease not renewed for this long is another worker's to take
  int max_attempts = 2;      // plannings started per job before it fails
  bool drain = false;        // end when no job is queued or being planned, instead of waiting for more
};

// Runs until drained (or forever). Returns the exit code.
int run_plan_worker(const PlanWorkerOptions& options);

}  // namespace hybridctl::cli
