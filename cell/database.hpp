#pragma once
// The shop cell's one connection to PostgreSQL (docs/cell.md), through libpq: the URI or
// connection string the libpq way (`postgresql://...`, `service=...`, or empty for the
// PG* environment), parameters always bound, never pasted into the SQL. Errors carry the
// statement's name and PostgreSQL's SQLSTATE and message.

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

struct pg_conn;
struct pg_result;

namespace hybridctl::cell {

// The database refused, or could not be reached. `sqlstate` is PostgreSQL's five-character
// code ("40001" a serialization failure, "57P01" the server shutting down), empty when the
// connection itself failed.
class DatabaseError : public std::runtime_error {
 public:
  DatabaseError(const std::string& what, std::string sqlstate)
      : std::runtime_error(what), sqlstate_(std::move(sqlstate)) {}
  const std::string& sqlstate() const { return sqlstate_; }
  // The connection broke (the server restarted, the network went): connect again and retry.
  bool connection_lost() const;

 private:
  std::string sqlstate_;
};

// A parameter of a statement: text, bytes (bytea), or SQL NULL.
struct Param {
  std::optional<std::string> value;
  bool binary = false;
  static Param text(std::string s) { return {std::move(s), false}; }
  static Param bytes(std::string s) { return {std::move(s), true}; }
  static Param number(std::int64_t n) { return {std::to_string(n), false}; }
  static Param real(double x);
  static Param null() { return {}; }
};

// The rows a statement returned, in text except bytea columns read as bytes.
class Rows {
 public:
  explicit Rows(pg_result* result);
  ~Rows();
  Rows(Rows&& other) noexcept;
  Rows& operator=(Rows&&) = delete;
  Rows(const Rows&) = delete;

  int size() const;
  bool empty() const { return size() == 0; }
  bool is_null(int row, int column) const;
  std::string text(int row, int column) const;
  std::int64_t number(int row, int column) const;
  // A bytea column as its bytes (the server sends it in hex).
  std::string bytes(int row, int column) const;
  int affected() const;  // rows an UPDATE, INSERT or DELETE touched

 private:
  pg_result* result_;
};

class Database {
 public:
  // Connects; throws DatabaseError naming the server libpq tried.
  explicit Database(const std::string& uri);
  ~Database();
  Database(const Database&) = delete;
  Database& operator=(const Database&) = delete;

  // Runs one statement. `name` says what it is for, in errors.
  Rows exec(const std::string& name, const std::string& sql, const std::vector<Param>& params = {});
  // Runs statements separated by semicolons, without parameters (a migration's DDL).
  void exec_script(const std::string& name, const std::string& sql);

  // BEGIN ... COMMIT around fn; ROLLBACK when it throws.
  template <class F>
  auto transaction(F&& fn) {
    exec("begin", "BEGIN");
    try {
      if constexpr (std::is_void_v<decltype(fn())>) {
        fn();
        exec("commit", "COMMIT");
      } else {
        auto out = fn();
        exec("commit", "COMMIT");
        return out;
      }
    } catch (...) {
      rollback_quietly();
      throw;
    }
  }

  // Notifications of LISTENed channels: waits up to `timeout_ms` for one; true when one came.
  bool wait_for_notification(int timeout_ms);

  const std::string& uri() const { return uri_; }

 private:
  void rollback_quietly();

  pg_conn* conn_ = nullptr;
  std::string uri_;
};

// The URI with any password replaced by "***", for messages and logs.
std::string redacted(const std::string& uri);

}  // namespace hybridctl::cell
