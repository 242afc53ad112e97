// `hybridctl cell`: the shop cell on PostgreSQL (docs/cell.md): init, machines, submit,
// plan-worker, status, report.

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <regex>
#include <thread>
#include <unistd.h>

#include "cell/jobs.hpp"
#include "cell/schema.hpp"
#include "cell/streams.hpp"
#include "cli/cell_machine_host.hpp"
#include "cli/cell_plan_worker.hpp"
#include "cli/commands.hpp"
#include "cli/ranges.hpp"
#include "common/error.hpp"
#include "config/machine_loader.hpp"
#include "gcode/files.hpp"
#include "plan/plan_machine.hpp"
#include "gcode/post.hpp"

namespace hybridctl::cli {
namespace {

namespace fs = std::filesystem;

struct CellArgs {
  std::string db;
  std::string name, machine_file, transport;  // machines add
  std::string part, machine;                  // submit
  double voxel = 0, tolerance = -1;
  int top = 0;
  PlanWorkerOptions worker;
  MachineHostOptions host;
  bool watch = false;
  int limit = 20;
  std::int64_t job = 0;
  std::string output;
};

// The database errors as exit codes: not reached 6, anything else 1, with what it said.
int guarded(const std::function<int()>& fn) {
  try {
    return fn();
  } catch (const cell::DatabaseError& e) {
    std::fflush(stdout);
    std::fprintf(stderr, "hybridctl: %s\n", e.what());
    return e.connection_lost() ? kUnreachable : kInternalError;
  }
}

int cell_init(const CellArgs& a) {
  cell::Database db(a.db);
  const cell::MigrationResult r = cell::migrate(db);
  if (r.from == r.to) std::printf("cell database %s: schema version %d, up to date\n", cell::redacted(a.db).c_str(), r.to);
  else std::printf("cell database %s: schema version %d -> %d\n", cell::redacted(a.db).c_str(), r.from, r.to);
  return kSuccess;
}

int machines_add(const CellArgs& a) {
  static const std::regex name_rule("^[A-Za-z0-9][A-Za-z0-9._-]{0,63}$");
  if (!std::regex_match(a.name, name_rule))
    throw InputError("machine name \"" + a.name + "\": expected 1-64 letters, digits, '.', '_' or '-', starting with a letter or digit");
  const std::string text = config::read_machine_text(a.machine_file);
  gcode::parse_postable_machine(text, a.machine_file);  // a machine file that does not load or post is not registered
  cell::Database db(a.db);
  cell::require_current_schema(db);
  cell::add_machine(db, {a.name, text, plan::machine_text_hash(text), a.transport});
  std::printf("machine %s registered (%s, hash %s)%s\n", a.name.c_str(), a.machine_file.c_str(),
              plan::machine_text_hash(text).c_str(), a.transport.empty() ? "" : (", controller at " + a.transport).c_str());
  return kSuccess;
}

int machines_list(const CellArgs& a) {
  cell::Database db(a.db);
  cell::require_current_schema(db);
  for (const cell::MachineEntry& m : cell::list_machines(db))
    std::printf("%-24s hash %s  %s\n", m.name.c_str(), m.hash.c_str(), m.transport.empty() ? "(no controller)" : m.transport.c_str());
  return kSuccess;
}

int submit(const CellArgs& a) {
  cell::Submission s;
  s.machine = a.machine;
  s.part_name = fs::path(a.part).filename().string();
  s.part_stl = gcode::read_text_file(a.part);
  if (s.part_stl.size() < 84) throw InputError(a.part + ": " + std::to_string(s.part_stl.size()) + " bytes: not an STL (at least 84 expected)");
  if (a.voxel > 0) s.request.voxel = a.voxel;
  if (a.tolerance >= 0) s.request.tolerance = a.tolerance;
  if (a.top > 0) s.request.top = a.top;
  cell::Database db(a.db);
  cell::require_current_schema(db);
  const std::int64_t id = cell::submit(db, s);
  std::printf("%lld\n", static_cast<long long>(id));
  return kSuccess;
}

// Each machine: its host, and the job bound to it with how far the controller got.
void print_machines(cell::Database& db) {
  std::printf("machines:\n");
  for (const cell::MachineState& m : cell::machine_states(db)) {
    std::string host = m.host.empty() ? "no host" : "host " + m.host + " (lease " + std::to_string(int(m.lease_left_s)) + " s)";
    std::printf("  %-16s %-36s", m.name.c_str(), host.c_str());
    if (m.job == 0) {
      std::printf(" idle\n");
      continue;
    }
    const double done = m.lines ? 100.0 * m.executed_line / m.lines : 0;
    std::printf(" job %lld (%s) line %u/%u (%.0f %%), sent through %u, recorded %.0f s ago%s%s\n", static_cast<long long>(m.job),
                m.part_name.c_str(), m.executed_line, m.lines, done, m.through_line, m.since_update_s,
                m.reason.empty() ? "" : "; stopped: ", m.reason.substr(0, m.reason.find('\n')).c_str());
  }
}

void print_status(cell::Database& db, int limit) {
  print_machines(db);
  std::printf("jobs:");
  for (const auto& [state, count] : cell::jobs_per_state(db)) std::printf(" %s %lld", state.c_str(), static_cast<long long>(count));
  std::printf("\n%6s  %-16s %-24s %-9s %8s  %-22s %s\n", "job", "machine", "part", "state", "attempts", "worker", "reason");
  for (const cell::JobRow& j : cell::recent_jobs(db, limit))
    std::printf("%6lld  %-16s %-24s %-9s %8d  %-22s %s\n", static_cast<long long>(j.id), j.machine.c_str(), j.part_name.c_str(),
                j.state.c_str(), j.attempts, j.worker.c_str(), j.reason.c_str());
  std::fflush(stdout);
}

int status(const CellArgs& a) {
  cell::Database db(a.db);
  cell::require_current_schema(db);
  print_status(db, a.limit);
  if (!a.watch) return kSuccess;
  db.exec("the outcome channel", "LISTEN cell_jobs_done");
  db.exec("the job channel", "LISTEN cell_jobs");
  for (;;) {
    db.wait_for_notification(2000);
    std::printf("\n");
    print_status(db, a.limit);
  }
}

// The job's plan directory, written whole under a temporary name and renamed.
int report(const CellArgs& a) {
  cell::Database db(a.db);
  cell::require_current_schema(db);
  const cell::JobRow j = cell::job(db, a.job);
  const auto files = cell::job_files(db, a.job);
  if (files.empty())
    throw InputError("job " + std::to_string(a.job) + " is " + j.state + " and has no files yet" +
                     (j.reason.empty() ? "" : " (" + j.reason + ")"));
  const fs::path target = a.output;
  std::error_code ec;
  if (fs::exists(target, ec)) throw InputError(a.output + ": exists; give a new directory for the job's files");
  const fs::path temp = target.parent_path() / ("." + target.filename().string() + ".tmp-" + std::to_string(getpid()));
  try {
    cell::write_job_files(files, temp, "job " + std::to_string(a.job));
    fs::rename(temp, target);
  } catch (...) {
    fs::remove_all(temp, ec);
    throw;
  }
  std::printf("job %lld (%s on %s, %s): %zu files in %s%s\n", static_cast<long long>(j.id), j.part_name.c_str(), j.machine.c_str(),
              j.state.c_str(), files.size(), a.output.c_str(),
              fs::exists(target / "report.html") ? ", the report in report.html" : "");
  return kSuccess;
}

void add_db_option(CLI::App* cmd, std::string& db) {
  cmd->add_option("--db", db,
                  "The cell's database: a libpq URI (postgresql://user@host:port/db) or connection string "
                  "(service=NAME); default $HYBRIDCTL_CELL_DB, else libpq's PG* environment")
      ->envname("HYBRIDCTL_CELL_DB");
}

}  // namespace

void add_cell_command(CLI::App& app, Runner& runner) {
  auto a = std::make_shared<CellArgs>();
  auto* cell = app.add_subcommand("cell", "A shop cell on PostgreSQL: machines, a queue of parts, plan workers on any host, a host "
                                          "per machine streaming its jobs (docs/cell.md)");
  cell->require_subcommand(1);
  auto on = [&runner, a](CLI::App* cmd, int (*fn)(const CellArgs&)) {
    add_db_option(cmd, a->db);
    cmd->callback([&runner, a, fn] { runner = [a, fn] { return guarded([&] { return fn(*a); }); }; });
  };
  on(cell->add_subcommand("init", "Create the cell's schema in the database, or migrate it to this hybridctl's (safe to run again)"),
     cell_init);
  auto* machines = cell->add_subcommand("machines", "The cell's machines");
  machines->require_subcommand(1);
  auto* add = machines->add_subcommand("add", "Register a machine (or replace its file and controller)");
  add->add_option("NAME", a->name, "The machine's name in the cell")->required();
  add->add_option("-m,--machine", a->machine_file, "Machine description (YAML)")->required();
  add->add_option("--transport", a->transport, "Where its controller listens (as `run --transport`)");
  on(add, machines_add);
  on(machines->add_subcommand("list", "The registered machines"), machines_list);
  auto* sub = cell->add_subcommand("submit", "Queue a part to plan for a machine; prints the job's id");
  sub->add_option("PART", a->part, "Part mesh (closed STL, mm)")->required();
  sub->add_option("-m,--machine", a->machine, "A registered machine's name")->required();
  sub->add_option("--voxel", a->voxel, "Voxel size in mm (default: the machine file's)")->check(greater_than(0));
  sub->add_option("--tolerance", a->tolerance, "Tolerance in mm on the STL (default: the machine file's)")->check(at_least(0));
  sub->add_option("--top", a->top, "How many plans (default: the machine file's)")->check(greater_than(0));
  on(sub, submit);
  auto* worker = cell->add_subcommand("plan-worker", "Plan the cell's jobs, one at a time, until stopped (or --drain)");
  worker->add_option("--name", a->worker.name, "How this worker signs its leases (default: host:pid)");
  worker->add_option("--lease", a->worker.lease_s, "Seconds a job's lease lasts unless renewed; a worker gone that long loses it")
      ->capture_default_str()
      ->check(between(1.0, 3600.0));
  worker->add_flag("--drain", a->worker.drain,
                   "End when no job is queued or being planned (by any worker) instead of waiting for more");
  on(worker, [](const CellArgs& args) {
    PlanWorkerOptions o = args.worker;
    o.db = args.db;
    return run_plan_worker(o);
  });
  auto* mh = cell->add_subcommand("machine-host",
                                   "Drive one machine: resume the job bound to it if its host died, then stream its planned "
                                   "jobs in order, each exactly once, the progress recorded in the database (exit 5 when the "
                                   "machine stopped first: the job stays bound to it)");
  mh->add_option("-m,--machine", a->host.machine, "The machine's name in the cell")->required();
  mh->add_option("--name", a->host.name, "How this host signs its lease on the machine (default: host:pid)");
  mh->add_option("-t,--transport", a->host.transport, "The controller's URI (default: the machine's registered one)");
  mh->add_option("--lease", a->host.lease_s,
                 "Seconds the host's lease on the machine lasts unless renewed; a host gone that long leaves the machine "
                 "to the next")
      ->capture_default_str()
      ->check(between(2.0, 3600.0));
  mh->add_option("--plan", a->host.plan_rank, "Which of each job's plans to run, by rank")->capture_default_str()->check(greater_than(0));
  mh->add_option("--from-line", a->host.from_line,
                 "After the controller lost the bound job's program: restart it at this line (the line the loss "
                 "message names, after checking the machine)")
      ->check(greater_than(0));
  mh->add_option("--wait-for-controller", a->host.wait_for_controller_s,
                 "Seconds to wait for a controller that stops answering mid-program before giving up (exit 6; the job "
                 "stays bound)")
      ->capture_default_str()
      ->check(between(0.0, 86400.0));
  mh->add_flag("-y,--yes", a->host.yes,
               "Unattended: stream each job without asking, continue after program stops, clear recoverable alarms");
  mh->add_flag("--drain", a->host.drain, "End when the machine has no planned job left instead of waiting for more");
  on(mh, [](const CellArgs& args) {
    MachineHostOptions o = args.host;
    o.db = args.db;
    return run_machine_host(o);
  });
  auto* st = cell->add_subcommand("status", "The machines with their hosts and bound jobs' progress; the queue: jobs per state and the newest jobs with their workers and reasons");
  st->add_flag("--watch", a->watch, "Print again whenever a job is submitted or finished, until interrupted");
  st->add_option("--limit", a->limit, "How many jobs to list")->capture_default_str()->check(between(1, 10000));
  on(st, status);
  auto* rep = cell->add_subcommand("report", "Write a job's plan directory (plan.json, report.html, ...) into a new directory");
  rep->add_option("JOB", a->job, "The job's id")->required()->check(greater_than(0));
  rep->add_option("-o,--output", a->output, "The directory to create")->required();
  on(rep, report);
}

}  // namespace hybridctl::cli
