#pragma once
// The cell's queue of parts to plan (docs/cell.md, "Jobs"): submitted with a copy of their
// machine file, claimed by any number of plan workers with a lease (`FOR UPDATE SKIP
// LOCKED`: no two workers ever take the same job), the lease renewed while the worker
// plans, and the outcome stored with the plan directory's files in one transaction that
// first checks the lease is still the worker's. A job whose worker died is taken again
// when its lease has run out; after `max_attempts` plannings that never finished it fails.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "cell/database.hpp"

namespace hybridctl::cell {

struct MachineEntry {
  std::string name;
  std::string machine_text;  // the machine file's YAML
  std::string hash;
  std::string transport;     // empty: none registered
};

// Registers a machine, or replaces the file and transport of one of that name (jobs
// already submitted keep the file they were submitted with).
void add_machine(Database& db, const MachineEntry& machine);
std::vector<MachineEntry> list_machines(Database& db);

// What `plan` is asked beyond the part and the machine; unset: the machine file's own.
struct PlanRequest {
  std::optional<double> voxel;
  std::optional<double> tolerance;
  std::optional<int> top;
  std::string json() const;
  static PlanRequest from_json(const std::string& text, const std::string& where);
};

struct Submission {
  std::string machine;    // a registered machine's name
  std::string part_name;  // the STL's file name, for people
  std::string part_stl;   // its bytes
  PlanRequest request;
};

// Stores the job and wakes the plan workers (NOTIFY cell_jobs); returns its id. Throws
// InputError when the machine is not registered.
std::int64_t submit(Database& db, const Submission& job);

struct Claim {
  std::int64_t job = 0;
  int attempt = 0;  // 1 the first planning; 2 after a worker died with it
  std::string part_name, part_stl, machine, machine_text;
  PlanRequest request;
};

// Takes the oldest job nobody plans (queued, or planning with a lease run out and fewer
// than `max_attempts` attempts) for `worker`, with a lease of `lease_s` seconds. Jobs whose
// lease ran out with `max_attempts` attempts fail first.
std::optional<Claim> claim_next(Database& db, const std::string& worker, double lease_s, int max_attempts);

// Extends the lease; false when the job is no longer this worker's (the lease ran out and
// another worker took it, or it was finished).
bool renew_lease(Database& db, std::int64_t job, const std::string& worker, double lease_s);

enum class JobState { Queued, Planning, Planned, Refused, Failed };
std::string state_name(JobState s);

struct Outcome {
  JobState state = JobState::Failed;  // Planned, Refused or Failed
  std::string reason;                 // for Refused and Failed
  std::vector<std::pair<std::string, std::string>> files;  // path in the plan directory, bytes
};

// Stores the outcome if the job is still this worker's; false (and nothing stored) when not.
bool finish(Database& db, std::int64_t job, const std::string& worker, const Outcome& outcome);

struct JobRow {
  std::int64_t id = 0;
  std::string machine, part_name, state, worker, reason, submitted_at, finished_at;
  int attempts = 0;
  std::int64_t files = 0;
};
// The newest `limit` jobs, newest first; and how many are in each state.
std::vector<JobRow> recent_jobs(Database& db, int limit);
std::vector<std::pair<std::string, std::int64_t>> jobs_per_state(Database& db);
// A job's stored files; throws InputError for a job that does not exist.
JobRow job(Database& db, std::int64_t id);
std::vector<std::pair<std::string, std::string>> job_files(Database& db, std::int64_t id);
// Writes them into `directory` (made if missing) by their stored paths; throws InputError
// for a path that would lie outside it (`whose`: the job, in the message).
void write_job_files(const std::vector<std::pair<std::string, std::string>>& files, const std::filesystem::path& directory,
                     const std::string& whose);

}  // namespace hybridctl::cell
