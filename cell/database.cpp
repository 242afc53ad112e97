#include "cell/database.hpp"

#include <poll.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <regex>

#include <libpq-fe.h>

namespace hybridctl::cell {
namespace {

std::string error_of(const pg_conn* conn) {
  std::string text = PQerrorMessage(conn);
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
  return text;
}

}  // namespace

bool DatabaseError::connection_lost() const {
  // Class 08: connection exceptions; 57P01-57P03: the server shutting down or starting.
  return sqlstate_.empty() || sqlstate_.rfind("08", 0) == 0 || sqlstate_ == "57P01" || sqlstate_ == "57P02" ||
         sqlstate_ == "57P03";
}

Param Param::real(double x) {
  char text[64];
  std::snprintf(text, sizeof text, "%.17g", x);
  return {std::string(text), false};
}

Rows::Rows(pg_result* result) : result_(result) {}
Rows::~Rows() {
  if (result_) PQclear(result_);
}
Rows::Rows(Rows&& other) noexcept : result_(other.result_) { other.result_ = nullptr; }

int Rows::size() const { return PQntuples(result_); }
bool Rows::is_null(int row, int column) const { return PQgetisnull(result_, row, column) != 0; }
std::string Rows::text(int row, int column) const {
  return std::string(PQgetvalue(result_, row, column), std::size_t(PQgetlength(result_, row, column)));
}
std::int64_t Rows::number(int row, int column) const { return std::strtoll(PQgetvalue(result_, row, column), nullptr, 10); }
std::string Rows::bytes(int row, int column) const {
  std::size_t length = 0;
  unsigned char* raw = PQunescapeBytea(reinterpret_cast<const unsigned char*>(PQgetvalue(result_, row, column)), &length);
  if (!raw) throw DatabaseError("cannot decode a bytea value (out of memory)", "");
  std::string out(reinterpret_cast<const char*>(raw), length);
  PQfreemem(raw);
  return out;
}
int Rows::affected() const {
  const char* n = PQcmdTuples(result_);
  return n && *n ? std::atoi(n) : 0;
}

Database::Database(const std::string& uri) : uri_(uri) {
  conn_ = PQconnectdb(uri.c_str());
  if (!conn_ || PQstatus(conn_) != CONNECTION_OK) {
    const std::string why = conn_ ? error_of(conn_) : "out of memory";
    if (conn_) PQfinish(conn_);
    conn_ = nullptr;
    throw DatabaseError("cannot connect to the cell's database " + redacted(uri) + ": " + why, "");
  }
  // Notices (NOTICE: relation already exists, skipping) are not the user's business.
  PQsetNoticeProcessor(conn_, [](void*, const char*) {}, nullptr);
}

Database::~Database() {
  if (conn_) PQfinish(conn_);
}

Rows Database::exec(const std::string& name, const std::string& sql, const std::vector<Param>& params) {
  std::vector<const char*> values;
  std::vector<int> lengths, formats;
  for (const Param& p : params) {
    values.push_back(p.value ? p.value->data() : nullptr);
    lengths.push_back(p.value ? int(p.value->size()) : 0);
    formats.push_back(p.binary ? 1 : 0);
  }
  pg_result* r = PQexecParams(conn_, sql.c_str(), int(params.size()), nullptr, values.data(), lengths.data(),
                              formats.data(), 0);
  const ExecStatusType status = r ? PQresultStatus(r) : PGRES_FATAL_ERROR;
  if (status == PGRES_COMMAND_OK || status == PGRES_TUPLES_OK) return Rows(r);
  const char* state = r ? PQresultErrorField(r, PG_DIAG_SQLSTATE) : nullptr;
  const std::string sqlstate = state ? state : "";
  const std::string why = error_of(conn_);
  if (r) PQclear(r);
  throw DatabaseError("the cell's database refused " + name + (sqlstate.empty() ? "" : " (SQLSTATE " + sqlstate + ")") +
                          ": " + why,
                      PQstatus(conn_) == CONNECTION_BAD ? "" : sqlstate);
}

void Database::exec_script(const std::string& name, const std::string& sql) {
  pg_result* r = PQexec(conn_, sql.c_str());
  const ExecStatusType status = r ? PQresultStatus(r) : PGRES_FATAL_ERROR;
  const char* state = r ? PQresultErrorField(r, PG_DIAG_SQLSTATE) : nullptr;
  const std::string sqlstate = state ? state : "";
  if (r) PQclear(r);
  if (status != PGRES_COMMAND_OK && status != PGRES_TUPLES_OK)
    throw DatabaseError("the cell's database refused " + name + ": " + error_of(conn_),
                        PQstatus(conn_) == CONNECTION_BAD ? "" : sqlstate);
}

void Database::rollback_quietly() {
  if (PQstatus(conn_) != CONNECTION_OK) return;
  if (pg_result* r = PQexec(conn_, "ROLLBACK")) PQclear(r);
}

bool Database::wait_for_notification(int timeout_ms) {
  auto take = [&] {
    PQconsumeInput(conn_);
    bool any = false;
    while (PGnotify* n = PQnotifies(conn_)) {
      any = true;
      PQfreemem(n);
    }
    return any;
  };
  if (take()) return true;
  pollfd p{PQsocket(conn_), POLLIN, 0};
  if (p.fd < 0) throw DatabaseError("the cell's database connection is closed", "");
  const int n = poll(&p, 1, timeout_ms);
  if (n < 0 && errno != EINTR) throw DatabaseError(std::string("waiting for the cell's database: ") + std::strerror(errno), "");
  if (n > 0 && !PQconsumeInput(conn_)) throw DatabaseError("the cell's database connection broke: " + error_of(conn_), "");
  return take();
}

std::string redacted(const std::string& uri) {
  static const std::regex in_uri(R"(^(postgres(?:ql)?://[^:/@]*:)[^@]*@)");
  static const std::regex in_keywords(R"((password\s*=\s*)('[^']*'|\S+))");
  return std::regex_replace(std::regex_replace(uri, in_uri, "$1***@"), in_keywords, "$1***");
}

}  // namespace hybridctl::cell
