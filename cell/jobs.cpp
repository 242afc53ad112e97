#include "cell/jobs.hpp"

#include <fstream>
#include <nlohmann/json.hpp>

#include "common/error.hpp"

namespace hybridctl::cell {

std::string PlanRequest::json() const {
  nlohmann::json j = nlohmann::json::object();
  if (voxel) j["voxel"] = *voxel;
  if (tolerance) j["tolerance"] = *tolerance;
  if (top) j["top"] = *top;
  return j.dump();
}

PlanRequest PlanRequest::from_json(const std::string& text, const std::string& where) {
  const nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
  if (!j.is_object()) throw InputError(where + ": the plan options are not a JSON object: " + text.substr(0, 200));
  PlanRequest r;
  for (const auto& [key, value] : j.items()) {
    if (key == "voxel" && value.is_number() && value.get<double>() > 0) r.voxel = value.get<double>();
    else if (key == "tolerance" && value.is_number() && value.get<double>() >= 0) r.tolerance = value.get<double>();
    else if (key == "top" && value.is_number_integer() && value.get<int>() > 0) r.top = value.get<int>();
    else
      throw InputError(where + ": plan option \"" + key + "\" = " + value.dump() +
                       ": expected voxel (mm > 0), tolerance (mm >= 0) or top (a count > 0)");
  }
  return r;
}

void add_machine(Database& db, const MachineEntry& m) {
  db.exec("the machine's registration",
          "INSERT INTO cell_machines (name, machine, hash, transport) VALUES ($1, $2, $3, $4) "
          "ON CONFLICT (name) DO UPDATE SET machine = EXCLUDED.machine, hash = EXCLUDED.hash, "
          "transport = EXCLUDED.transport, added_at = now()",
          {Param::text(m.name), Param::text(m.machine_text), Param::text(m.hash),
           m.transport.empty() ? Param::null() : Param::text(m.transport)});
}

std::vector<MachineEntry> list_machines(Database& db) {
  const Rows rows = db.exec("the machines", "SELECT name, machine, hash, coalesce(transport, '') FROM cell_machines ORDER BY name");
  std::vector<MachineEntry> out;
  for (int r = 0; r < rows.size(); ++r) out.push_back({rows.text(r, 0), rows.text(r, 1), rows.text(r, 2), rows.text(r, 3)});
  return out;
}

std::int64_t submit(Database& db, const Submission& job) {
  return db.transaction([&] {
    const Rows m = db.exec("the machine lookup", "SELECT machine, hash FROM cell_machines WHERE name = $1",
                           {Param::text(job.machine)});
    if (m.empty())
      throw InputError("--machine " + job.machine + ": no machine of that name in the cell (`hybridctl cell machines list`; "
                       "register it with `hybridctl cell machines add NAME --machine FILE`)");
    const Rows id = db.exec("the job's submission",
                            "INSERT INTO cell_jobs (machine, part_name, part, machine_text, machine_hash, options) "
                            "VALUES ($1, $2, $3, $4, $5, $6::jsonb) RETURNING id",
                            {Param::text(job.machine), Param::text(job.part_name), Param::bytes(job.part_stl),
                             Param::text(m.text(0, 0)), Param::text(m.text(0, 1)), Param::text(job.request.json())});
    const std::int64_t job_id = id.number(0, 0);
    db.exec("the submission event", "INSERT INTO cell_job_events (job, event) VALUES ($1, 'submitted')",
            {Param::number(job_id)});
    db.exec("the workers' wake-up", "NOTIFY cell_jobs");
    return job_id;
  });
}

std::optional<Claim> claim_next(Database& db, const std::string& worker, double lease_s, int max_attempts) {
  return db.transaction([&]() -> std::optional<Claim> {
    const Rows given_up = db.exec(
        "the jobs given up",
        "UPDATE cell_jobs SET state = 'failed', finished_at = now(), reason = 'planning was started ' || attempts || "
        "' times and never finished (each time its worker stopped renewing its lease): not tried again' "
        "WHERE state = 'planning' AND lease_until < now() AND attempts >= $1 RETURNING id",
        {Param::number(max_attempts)});
    for (int r = 0; r < given_up.size(); ++r)
      db.exec("the failure event", "INSERT INTO cell_job_events (job, worker, event, detail) VALUES ($1, $2, 'failed', 'lease ran out')",
              {Param::number(given_up.number(r, 0)), Param::text(worker)});
    const Rows rows = db.exec(
        "the claim",
        "UPDATE cell_jobs j SET state = 'planning', worker = $1, lease_until = now() + $2 * interval '1 second', "
        "attempts = j.attempts + 1 "
        "FROM (SELECT id FROM cell_jobs WHERE state = 'queued' OR (state = 'planning' AND lease_until < now() AND attempts < $3) "
        "      ORDER BY id FOR UPDATE SKIP LOCKED LIMIT 1) next "
        "WHERE j.id = next.id "
        "RETURNING j.id, j.attempts, j.part_name, j.part, j.machine, j.machine_text, j.options::text",
        {Param::text(worker), Param::real(lease_s), Param::number(max_attempts)});
    if (rows.empty()) return std::nullopt;
    Claim c;
    c.job = rows.number(0, 0);
    c.attempt = int(rows.number(0, 1));
    c.part_name = rows.text(0, 2);
    c.part_stl = rows.bytes(0, 3);
    c.machine = rows.text(0, 4);
    c.machine_text = rows.text(0, 5);
    c.request = PlanRequest::from_json(rows.text(0, 6), "job " + std::to_string(c.job));
    db.exec("the claim event", "INSERT INTO cell_job_events (job, worker, event, detail) VALUES ($1, $2, 'claimed', $3)",
            {Param::number(c.job), Param::text(worker), Param::text("attempt " + std::to_string(c.attempt))});
    return c;
  });
}

bool renew_lease(Database& db, std::int64_t job, const std::string& worker, double lease_s) {
  return db.exec("the lease's renewal",
                 "UPDATE cell_jobs SET lease_until = now() + $3 * interval '1 second' "
                 "WHERE id = $1 AND worker = $2 AND state = 'planning'",
                 {Param::number(job), Param::text(worker), Param::real(lease_s)})
             .affected() == 1;
}

std::string state_name(JobState s) {
  switch (s) {
    case JobState::Queued: return "queued";
    case JobState::Planning: return "planning";
    case JobState::Planned: return "planned";
    case JobState::Refused: return "refused";
    case JobState::Failed: return "failed";
  }
  return "failed";
}

bool finish(Database& db, std::int64_t job, const std::string& worker, const Outcome& outcome) {
  return db.transaction([&] {
    const Rows mine = db.exec("the lease check",
                              "SELECT 1 FROM cell_jobs WHERE id = $1 AND worker = $2 AND state = 'planning' FOR UPDATE",
                              {Param::number(job), Param::text(worker)});
    if (mine.empty()) return false;
    db.exec("the old files' removal", "DELETE FROM cell_job_files WHERE job = $1", {Param::number(job)});
    for (const auto& [path, content] : outcome.files)
      db.exec("the file " + path, "INSERT INTO cell_job_files (job, path, content) VALUES ($1, $2, $3)",
              {Param::number(job), Param::text(path), Param::bytes(content)});
    const std::string state = state_name(outcome.state);
    db.exec("the outcome",
            "UPDATE cell_jobs SET state = $2, reason = $3, finished_at = now(), lease_until = NULL WHERE id = $1",
            {Param::number(job), Param::text(state), outcome.reason.empty() ? Param::null() : Param::text(outcome.reason)});
    db.exec("the outcome event", "INSERT INTO cell_job_events (job, worker, event, detail) VALUES ($1, $2, $3, $4)",
            {Param::number(job), Param::text(worker), Param::text(state),
             outcome.reason.empty() ? Param::null() : Param::text(outcome.reason)});
    db.exec("the waiters' wake-up", "NOTIFY cell_jobs_done");
    return true;
  });
}

namespace {

constexpr const char* kJobColumns =
    "j.id, j.machine, j.part_name, j.state, coalesce(j.worker, ''), coalesce(j.reason, ''), "
    "to_char(j.submitted_at, 'YYYY-MM-DD HH24:MI:SS'), coalesce(to_char(j.finished_at, 'YYYY-MM-DD HH24:MI:SS'), ''), "
    "j.attempts, (SELECT count(*) FROM cell_job_files f WHERE f.job = j.id)";

JobRow job_row(const Rows& rows, int r) {
  return {rows.number(r, 0), rows.text(r, 1), rows.text(r, 2), rows.text(r, 3), rows.text(r, 4), rows.text(r, 5),
          rows.text(r, 6),   rows.text(r, 7), int(rows.number(r, 8)), rows.number(r, 9)};
}

}  // namespace

std::vector<JobRow> recent_jobs(Database& db, int limit) {
  const Rows rows = db.exec("the recent jobs", std::string("SELECT ") + kJobColumns + " FROM cell_jobs j ORDER BY j.id DESC LIMIT $1",
                            {Param::number(limit)});
  std::vector<JobRow> out;
  for (int r = 0; r < rows.size(); ++r) out.push_back(job_row(rows, r));
  return out;
}

std::vector<std::pair<std::string, std::int64_t>> jobs_per_state(Database& db) {
  const Rows rows = db.exec("the jobs per state", "SELECT state, count(*) FROM cell_jobs GROUP BY state ORDER BY state");
  std::vector<std::pair<std::string, std::int64_t>> out;
  for (int r = 0; r < rows.size(); ++r) out.emplace_back(rows.text(r, 0), rows.number(r, 1));
  return out;
}

JobRow job(Database& db, std::int64_t id) {
  const Rows rows = db.exec("the job", std::string("SELECT ") + kJobColumns + " FROM cell_jobs j WHERE j.id = $1",
                            {Param::number(id)});
  if (rows.empty()) throw InputError("job " + std::to_string(id) + ": no such job in the cell (`hybridctl cell status`)");
  return job_row(rows, 0);
}

std::vector<std::pair<std::string, std::string>> job_files(Database& db, std::int64_t id) {
  const Rows rows = db.exec("the job's files", "SELECT path, content FROM cell_job_files WHERE job = $1 ORDER BY path",
                            {Param::number(id)});
  std::vector<std::pair<std::string, std::string>> out;
  for (int r = 0; r < rows.size(); ++r) out.emplace_back(rows.text(r, 0), rows.bytes(r, 1));
  return out;
}

void write_job_files(const std::vector<std::pair<std::string, std::string>>& files, const std::filesystem::path& directory,
                     const std::string& whose) {
  std::filesystem::create_directories(directory);
  const std::string inside = directory.lexically_normal().string();
  for (const auto& [path, content] : files) {
    const std::filesystem::path p = directory / path;
    if (p.lexically_normal().string().rfind(inside, 0) != 0)
      throw InputError(whose + ": stored file \"" + path + "\" lies outside the job's directory");
    std::filesystem::create_directories(p.parent_path());
    std::ofstream out(p, std::ios::binary);
    out << content;
    if (!out.flush()) throw InputError(p.string() + ": cannot be written");
  }
}

}  // namespace hybridctl::cell
