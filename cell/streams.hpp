#pragma once
// The cell's machines at work (docs/cell.md, "Machine hosts"): one host process drives a
// machine at a time, by a lease on the machine's row; a planned job is bound to its
// machine when its program is stored (state `streaming`), and stays bound, whatever
// happens to the host, until the machine completed it (`done`). A machine has at most one
// bound job (a unique index says so), and the next host for that machine resumes it
// before it takes anything new.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "cell/database.hpp"
#include "drivers/job_record.hpp"

namespace hybridctl::cell {

struct MachineLease {
  bool ours = false;
  std::string holder;        // when not ours: the host that holds it
  double seconds_left = 0;   // of the holder's lease
  std::string transport;     // the machine's registered controller
  std::string machine_text;  // its registered machine file
};

// Takes (or renews) the machine's lease for `host`, unless another host holds one that
// has not run out. Throws InputError for a machine that is not registered.
MachineLease take_machine(Database& db, const std::string& machine, const std::string& host, double lease_s);
// Gives the lease up (a host that ends cleanly): the next host need not wait for it.
void release_machine(Database& db, const std::string& machine, const std::string& host);

// A job bound to a machine: its program and what its record says.
struct BoundJob {
  std::int64_t job = 0;
  std::string part_name, machine_text;
  int plan_rank = 1;
  std::string original;  // the program as exported and proven
  std::string program;   // as streamed: the original, or a restart of it
  std::uint32_t restart_from_line = 0, restart_preamble_lines = 0;
  std::string host;      // the host that streamed it last
  std::string reason;    // why the machine stopped, when it did
  drivers::JournalProgress progress;
};

// The job bound to the machine, if any.
std::optional<BoundJob> bound_job(Database& db, const std::string& machine);

struct PlannedJob {
  std::int64_t job = 0;
  std::string part_name;
};
// The oldest planned job for the machine.
std::optional<PlannedJob> next_planned(Database& db, const std::string& machine);

// Binds the job to its machine with its program: false (and nothing stored) when the
// host no longer holds the machine's lease or the job is no longer planned.
bool bind_job(Database& db, std::int64_t job, const std::string& machine, const std::string& host, int plan_rank,
              const std::string& program);
// The program of a planned job could not be made (its plan does not prove on this
// hybridctl): the job fails with the reason.
void fail_planned_job(Database& db, std::int64_t job, const std::string& host, const std::string& reason);
// A bound job's program becomes a restart (a controller lost it): progress starts over.
bool restart_bound_job(Database& db, std::int64_t job, const std::string& machine, const std::string& host,
                       const std::string& program, std::uint32_t from_line, std::uint32_t preamble_lines);
// The machine stopped before the end: the job stays bound, with the reason.
void stopped_on_machine(Database& db, std::int64_t job, const std::string& host, const std::string& reason);

// A machine as `cell status` shows it: who drives it, and the job bound to it.
struct MachineState {
  std::string name;
  std::string host;            // empty: none, or its lease ran out
  double lease_left_s = 0;
  std::int64_t job = 0;        // 0: no job bound
  std::string part_name, reason;
  std::uint32_t lines = 0, executed_line = 0, through_line = 0;
  double since_update_s = 0;   // since its record was last written
};
std::vector<MachineState> machine_states(Database& db);

// Whether `host` holds the machine's lease, renewing it for `lease_s` when it does. In a
// transaction, it fences what follows: a host whose lease another took writes nothing.
bool renew_machine(Database& db, const std::string& machine, const std::string& host, double lease_s);

}  // namespace hybridctl::cell
