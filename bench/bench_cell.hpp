#pragma once
// The shop cell's benchmarks' database: one PostgreSQL server of the program's own on
// 127.0.0.1 (tests/cell/postgres_server.hpp), with the cell's schema and a machine "mill",
// made at first use and stopped when the program ends. Header-only, for bench programs.

#include "cell/database.hpp"
#include "cell/jobs.hpp"
#include "cell/schema.hpp"
#include "tests/cell/postgres_server.hpp"

namespace hybridctl::bench {

inline cell::testing::PostgresServer& cell_server() {
  static cell::testing::PostgresServer s;
  static const bool ready = [] {
    cell::Database db(s.uri());
    cell::migrate(db);
    cell::add_machine(db, {"mill", "name: mill\n", "0", ""});
    return true;
  }();
  (void)ready;
  return s;
}

}  // namespace hybridctl::bench
