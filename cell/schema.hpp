#pragma once
// The cell's schema in PostgreSQL (docs/cell.md, "Schema"), as numbered migrations: each
// applied once, in order, in its own transaction, under an advisory lock, so that any
// number of `cell init` runs at once leave the same database.

#include <string>
#include <vector>

#include "cell/database.hpp"

namespace hybridctl::cell {

struct Migration {
  int version;
  std::string what;
  std::string sql;
};

// Every migration, oldest first.
const std::vector<Migration>& migrations();

struct MigrationResult {
  int from = 0;  // the schema's version before (0: none)
  int to = 0;    // and after
};

// Brings the database to the newest schema. Throws DatabaseError; refuses (InputError) a
// database whose schema is newer than this hybridctl knows.
MigrationResult migrate(Database& db);

// The schema's version, 0 when the cell was never initialised; throws InputError when it
// is not the one this hybridctl knows (run `cell init`).
int schema_version(Database& db);
void require_current_schema(Database& db);

}  // namespace hybridctl::cell
