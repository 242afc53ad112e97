#pragma once
// `hybridctl cell machine-host` (docs/cell.md, "Machine hosts"): drives one machine of the
// cell. It takes the machine's lease (one host per machine; a second waits as a standby),
// resumes the job bound to the machine if a host died with it, then takes the machine's
// planned jobs in order: the operator confirms each (or --yes), its plan is exported and
// proven as `run` does, the program is stored and the job bound to the machine in one
// transaction, and the program is streamed exactly once with `run`'s streamer, its
// record in the database (cell/stream_journal.hpp).

#include <string>

namespace hybridctl::cli {

struct MachineHostOptions {
  std::string db;            // libpq URI or connection string
  std::string machine;       // the machine's name in the cell
  std::string name;          // how the host signs its lease; empty: host:pid
  std::string transport;     // empty: the machine's registered one
  double lease_s = 30;       // a host silent this long loses the machine to the next
  int plan_rank = 1;         // which of a job's plans to run
  unsigned from_line = 0;    // restart the bound job's program there (the controller lost it)
  bool yes = false;          // unattended: no confirmation, program stops continued, alarms cleared
  bool drain = false;        // end when the machine has no planned job left
  double wait_for_controller_s = 120;
};

// Runs until drained, refused, or the machine stopped. Returns the exit code.
int run_machine_host(const MachineHostOptions& options);

}  // namespace hybridctl::cli
