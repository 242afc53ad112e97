#include "cell/schema.hpp"

#include "common/error.hpp"

namespace hybridctl::cell {
namespace {

// Taken by every migration run: migrations never interleave.
constexpr const char* kMigrationLock = "SELECT pg_advisory_xact_lock(4242000001)";

}  // namespace

const std::vector<Migration>& migrations() {
  static const std::vector<Migration> all = {
      {1, "machines, jobs and their files and events",
       R"sql(
CREATE TABLE cell_machines (
  name        text PRIMARY KEY CHECK (name ~ '^[A-Za-z0-9][A-Za-z0-9._-]{0,63}$'),
  machine     text NOT NULL,            -- the machine file's text
  hash        text NOT NULL,            -- FNV-1a 64 of that text (plan::machine_text_hash)
  transport   text,                     -- where its controller listens (run --transport)
  added_at    timestamptz NOT NULL DEFAULT now()
);
CREATE TABLE cell_jobs (
  id           bigserial PRIMARY KEY,
  machine      text NOT NULL REFERENCES cell_machines (name),
  part_name    text NOT NULL,
  part         bytea NOT NULL,          -- the STL as submitted
  machine_text text NOT NULL,           -- the machine file as it was at submission
  machine_hash text NOT NULL,
  options      jsonb NOT NULL DEFAULT '{}',
  state        text NOT NULL DEFAULT 'queued'
               CHECK (state IN ('queued', 'planning', 'planned', 'refused', 'failed')),
  attempts     integer NOT NULL DEFAULT 0,  -- plannings started
  worker       text,                    -- who holds the lease, or last held it
  lease_until  timestamptz,
  reason       text,                    -- why refused or failed
  submitted_at timestamptz NOT NULL DEFAULT now(),
  finished_at  timestamptz
);
CREATE INDEX cell_jobs_to_plan ON cell_jobs (id) WHERE state IN ('queued', 'planning');
CREATE TABLE cell_job_files (
  job      bigint NOT NULL REFERENCES cell_jobs (id) ON DELETE CASCADE,
  path     text NOT NULL,                -- in the plan directory: plan.json, report.html, ...
  content  bytea NOT NULL,
  PRIMARY KEY (job, path)
);
CREATE TABLE cell_job_events (
  id      bigserial PRIMARY KEY,
  job     bigint NOT NULL REFERENCES cell_jobs (id) ON DELETE CASCADE,
  at      timestamptz NOT NULL DEFAULT now(),
  worker  text,
  event   text NOT NULL,                 -- submitted, claimed, lease-lost, planned, refused, failed
  detail  text
);
CREATE INDEX cell_job_events_job ON cell_job_events (job);
-- The jobs' parts and plans are the shop's: the cell's role (the owner) alone reads them.
REVOKE ALL ON cell_schema, cell_machines, cell_jobs, cell_job_files, cell_job_events FROM PUBLIC;
)sql"},
      {2, "machine hosts: the machines' leases, the jobs bound to them with their programs and progress",
       R"sql(
ALTER TABLE cell_jobs DROP CONSTRAINT cell_jobs_state_check;
ALTER TABLE cell_jobs ADD CONSTRAINT cell_jobs_state_check
  CHECK (state IN ('queued', 'planning', 'planned', 'refused', 'failed', 'streaming', 'done'));
-- A machine runs one program at a time: at most one job is bound to it.
CREATE UNIQUE INDEX cell_jobs_bound_to_machine ON cell_jobs (machine) WHERE state = 'streaming';
ALTER TABLE cell_machines
  ADD COLUMN host text,                 -- the machine host that drives it
  ADD COLUMN host_lease_until timestamptz;
CREATE TABLE cell_streams (
  job            bigint PRIMARY KEY REFERENCES cell_jobs (id) ON DELETE CASCADE,
  plan_rank      integer NOT NULL,
  original       text NOT NULL,         -- the program as exported and proven
  program        text NOT NULL,         -- as streamed: the original, or its restart after a controller loss
  identity       text NOT NULL,         -- of `program` (protocol::program_identity), hex
  lines          integer NOT NULL,
  restart_from_line      integer NOT NULL DEFAULT 0,
  restart_preamble_lines integer NOT NULL DEFAULT 0,
  host           text NOT NULL,         -- the host that streams it, or last did
  last_chunk     bigint NOT NULL DEFAULT 0,
  through_line   bigint NOT NULL DEFAULT 0,
  executed_line  bigint NOT NULL DEFAULT 0,
  completed      boolean NOT NULL DEFAULT false,
  lost           boolean NOT NULL DEFAULT false,
  lost_executed_line bigint NOT NULL DEFAULT 0,
  lost_accepted_line bigint NOT NULL DEFAULT 0,
  held_by_host   boolean NOT NULL DEFAULT false,
  started_at     timestamptz NOT NULL DEFAULT now(),
  updated_at     timestamptz NOT NULL DEFAULT now()
);
REVOKE ALL ON cell_streams FROM PUBLIC;
)sql"},
  };
  return all;
}

int schema_version(Database& db) {
  const Rows exists = db.exec("the schema's table lookup", "SELECT to_regclass('cell_schema') IS NOT NULL");
  if (exists.text(0, 0) != "t") return 0;
  const Rows v = db.exec("the schema's version", "SELECT coalesce(max(version), 0) FROM cell_schema");
  return int(v.number(0, 0));
}

void require_current_schema(Database& db) {
  const int have = schema_version(db);
  const int want = migrations().back().version;
  if (have == want) return;
  if (have == 0)
    throw InputError(redacted(db.uri()) + ": not a hybridctl cell database (no cell_schema table): run `hybridctl cell init --db URI` first");
  throw InputError(redacted(db.uri()) + ": the cell's schema is version " + std::to_string(have) + ", this hybridctl knows " +
                   std::to_string(want) + (have < want ? ": run `hybridctl cell init --db URI` to migrate it" : ": use a newer hybridctl"));
}

MigrationResult migrate(Database& db) {
  MigrationResult result;
  db.transaction([&] {
    db.exec("the migration lock", kMigrationLock);  // two inits at once would race on the table's type
    db.exec_script("the schema's version table",
                   "CREATE TABLE IF NOT EXISTS cell_schema (version integer PRIMARY KEY, what text NOT NULL, "
                   "applied_at timestamptz NOT NULL DEFAULT now())");
  });
  result.from = result.to = schema_version(db);
  const int newest = migrations().back().version;
  if (result.from > newest)
    throw InputError(redacted(db.uri()) + ": the cell's schema is version " + std::to_string(result.from) +
                     ", newer than this hybridctl knows (" + std::to_string(newest) + "): use a newer hybridctl");
  for (const Migration& m : migrations()) {
    db.transaction([&] {
      db.exec("the migration lock", kMigrationLock);
      // Another `cell init` may have applied it while this one waited for the lock.
      const Rows done = db.exec("the migration check", "SELECT 1 FROM cell_schema WHERE version = $1",
                                {Param::number(m.version)});
      if (!done.empty()) return;
      db.exec_script("migration " + std::to_string(m.version) + " (" + m.what + ")", m.sql);
      db.exec("the migration record", "INSERT INTO cell_schema (version, what) VALUES ($1, $2)",
              {Param::number(m.version), Param::text(m.what)});
    });
    result.to = m.version;
  }
  return result;
}

}  // namespace hybridctl::cell
