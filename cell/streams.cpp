#include "cell/streams.hpp"

#include "common/error.hpp"
#include "protocol/chunk.hpp"

namespace hybridctl::cell {
namespace {

std::string hex(std::uint64_t v) {
  char b[17];
  std::snprintf(b, sizeof b, "%016llx", static_cast<unsigned long long>(v));
  return b;
}

void event(Database& db, std::int64_t job, const std::string& host, const std::string& what, const std::string& detail) {
  db.exec("the job's event", "INSERT INTO cell_job_events (job, worker, event, detail) VALUES ($1, $2, $3, $4)",
          {Param::number(job), Param::text(host), Param::text(what), detail.empty() ? Param::null() : Param::text(detail)});
}

// In a transaction: whether `host` holds the machine's lease, the row locked until the
// end so that no other host takes it meanwhile.
bool holds_machine(Database& db, const std::string& machine, const std::string& host) {
  return !db.exec("the machine's lease check",
                  "SELECT 1 FROM cell_machines WHERE name = $1 AND host = $2 AND host_lease_until >= now() FOR UPDATE",
                  {Param::text(machine), Param::text(host)})
              .empty();
}

}  // namespace

MachineLease take_machine(Database& db, const std::string& machine, const std::string& host, double lease_s) {
  MachineLease lease;
  const Rows taken = db.exec("the machine's lease",
                             "UPDATE cell_machines SET host = $2, host_lease_until = now() + make_interval(secs => $3) "
                             "WHERE name = $1 AND (host IS NULL OR host = $2 OR host_lease_until < now()) "
                             "RETURNING coalesce(transport, ''), machine",
                             {Param::text(machine), Param::text(host), Param::real(lease_s)});
  if (!taken.empty()) {
    lease.ours = true;
    lease.transport = taken.text(0, 0);
    lease.machine_text = taken.text(0, 1);
    return lease;
  }
  const Rows held = db.exec("the machine's holder",
                            "SELECT coalesce(host, ''), extract(epoch FROM host_lease_until - now()) FROM cell_machines WHERE name = $1",
                            {Param::text(machine)});
  if (held.empty())
    throw InputError("--machine " + machine + ": no machine of that name in the cell (`hybridctl cell machines list`)");
  lease.holder = held.text(0, 0);
  lease.seconds_left = held.is_null(0, 1) ? 0 : std::stod(held.text(0, 1));
  return lease;
}

void release_machine(Database& db, const std::string& machine, const std::string& host) {
  db.exec("the machine's release", "UPDATE cell_machines SET host = NULL, host_lease_until = NULL WHERE name = $1 AND host = $2",
          {Param::text(machine), Param::text(host)});
}

std::vector<MachineState> machine_states(Database& db) {
  const Rows r = db.exec(
      "the machines' states",
      "SELECT m.name, CASE WHEN m.host_lease_until >= now() THEN m.host ELSE '' END, "
      "coalesce(extract(epoch FROM m.host_lease_until - now()), 0), coalesce(j.id, 0), coalesce(j.part_name, ''), "
      "coalesce(j.reason, ''), coalesce(s.lines, 0), coalesce(s.executed_line, 0), coalesce(s.through_line, 0), "
      "coalesce(extract(epoch FROM now() - s.updated_at), 0) "
      "FROM cell_machines m LEFT JOIN cell_jobs j ON j.machine = m.name AND j.state = 'streaming' "
      "LEFT JOIN cell_streams s ON s.job = j.id ORDER BY m.name");
  std::vector<MachineState> out;
  for (int i = 0; i < r.size(); ++i) {
    MachineState m;
    m.name = r.text(i, 0);
    m.host = r.text(i, 1);
    m.lease_left_s = std::stod(r.text(i, 2));
    m.job = r.number(i, 3);
    m.part_name = r.text(i, 4);
    m.reason = r.text(i, 5);
    m.lines = std::uint32_t(r.number(i, 6));
    m.executed_line = std::uint32_t(r.number(i, 7));
    m.through_line = std::uint32_t(r.number(i, 8));
    m.since_update_s = std::stod(r.text(i, 9));
    out.push_back(std::move(m));
  }
  return out;
}

bool renew_machine(Database& db, const std::string& machine, const std::string& host, double lease_s) {
  return db.exec("the machine's lease renewal",
                 "UPDATE cell_machines SET host_lease_until = now() + make_interval(secs => $3) "
                 "WHERE name = $1 AND host = $2 AND host_lease_until >= now()",
                 {Param::text(machine), Param::text(host), Param::real(lease_s)})
             .affected() == 1;
}

std::optional<BoundJob> bound_job(Database& db, const std::string& machine) {
  const Rows r = db.exec(
      "the machine's bound job",
      "SELECT j.id, j.part_name, j.machine_text, s.plan_rank, s.original, s.program, s.restart_from_line, "
      "s.restart_preamble_lines, s.host, coalesce(j.reason, ''), s.last_chunk, s.through_line, s.executed_line, "
      "s.completed, s.lost, s.lost_executed_line, s.lost_accepted_line, s.held_by_host "
      "FROM cell_jobs j JOIN cell_streams s ON s.job = j.id WHERE j.machine = $1 AND j.state = 'streaming'",
      {Param::text(machine)});
  if (r.empty()) return std::nullopt;
  BoundJob b;
  b.job = r.number(0, 0);
  b.part_name = r.text(0, 1);
  b.machine_text = r.text(0, 2);
  b.plan_rank = int(r.number(0, 3));
  b.original = r.text(0, 4);
  b.program = r.text(0, 5);
  b.restart_from_line = std::uint32_t(r.number(0, 6));
  b.restart_preamble_lines = std::uint32_t(r.number(0, 7));
  b.host = r.text(0, 8);
  b.reason = r.text(0, 9);
  b.progress.last_chunk = std::uint32_t(r.number(0, 10));
  b.progress.through_line = std::uint32_t(r.number(0, 11));
  b.progress.executed_line = std::uint32_t(r.number(0, 12));
  b.progress.completed = r.text(0, 13) == "t";
  b.progress.lost = r.text(0, 14) == "t";
  b.progress.lost_executed_line = std::uint32_t(r.number(0, 15));
  b.progress.lost_accepted_line = std::uint32_t(r.number(0, 16));
  b.progress.held_by_host = r.text(0, 17) == "t";
  return b;
}

std::optional<PlannedJob> next_planned(Database& db, const std::string& machine) {
  const Rows r = db.exec("the machine's next planned job",
                         "SELECT id, part_name FROM cell_jobs WHERE machine = $1 AND state = 'planned' ORDER BY id LIMIT 1",
                         {Param::text(machine)});
  if (r.empty()) return std::nullopt;
  return PlannedJob{r.number(0, 0), r.text(0, 1)};
}

bool bind_job(Database& db, std::int64_t job, const std::string& machine, const std::string& host, int plan_rank,
              const std::string& program) {
  return db.transaction([&] {
    if (!holds_machine(db, machine, host)) return false;
    const Rows bound = db.exec("the job's binding",
                               "UPDATE cell_jobs SET state = 'streaming', worker = $2, reason = NULL "
                               "WHERE id = $1 AND state = 'planned' AND machine = $3",
                               {Param::number(job), Param::text(host), Param::text(machine)});
    if (bound.affected() != 1) return false;
    const auto lines = protocol::program_lines(program);
    db.exec("the job's program",
            "INSERT INTO cell_streams (job, plan_rank, original, program, identity, lines, host) "
            "VALUES ($1, $2, $3, $3, $4, $5, $6)",
            {Param::number(job), Param::number(plan_rank), Param::text(program),
             Param::text(hex(protocol::program_identity(lines))), Param::number(std::int64_t(lines.size())), Param::text(host)});
    event(db, job, host, "bound", "plan " + std::to_string(plan_rank) + ", " + std::to_string(lines.size()) + " lines");
    db.exec("the watchers' wake-up", "NOTIFY cell_jobs_done");
    return true;
  });
}

void fail_planned_job(Database& db, std::int64_t job, const std::string& host, const std::string& reason) {
  db.transaction([&] {
    db.exec("the job's failure",
            "UPDATE cell_jobs SET state = 'failed', reason = $2, finished_at = now() WHERE id = $1 AND state = 'planned'",
            {Param::number(job), Param::text(reason)});
    event(db, job, host, "failed", reason);
    db.exec("the watchers' wake-up", "NOTIFY cell_jobs_done");
  });
}

bool restart_bound_job(Database& db, std::int64_t job, const std::string& machine, const std::string& host,
                       const std::string& program, std::uint32_t from_line, std::uint32_t preamble_lines) {
  return db.transaction([&] {
    if (!holds_machine(db, machine, host)) return false;
    const auto lines = protocol::program_lines(program);
    db.exec("the job's restart",
            "UPDATE cell_streams SET program = $2, identity = $3, lines = $4, restart_from_line = $5, "
            "restart_preamble_lines = $6, host = $7, last_chunk = 0, through_line = 0, executed_line = 0, completed = false, "
            "lost = false, lost_executed_line = 0, lost_accepted_line = 0, held_by_host = false, updated_at = now() "
            "WHERE job = $1",
            {Param::number(job), Param::text(program), Param::text(hex(protocol::program_identity(lines))),
             Param::number(std::int64_t(lines.size())), Param::number(from_line), Param::number(preamble_lines),
             Param::text(host)});
    event(db, job, host, "restarted", "from line " + std::to_string(from_line) + " of the original program");
    return true;
  });
}

void stopped_on_machine(Database& db, std::int64_t job, const std::string& host, const std::string& reason) {
  db.transaction([&] {
    db.exec("the job's stop", "UPDATE cell_jobs SET reason = $2 WHERE id = $1", {Param::number(job), Param::text(reason)});
    event(db, job, host, "stopped", reason);
    db.exec("the watchers' wake-up", "NOTIFY cell_jobs_done");
  });
}

}  // namespace hybridctl::cell
