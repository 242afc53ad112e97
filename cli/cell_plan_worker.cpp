#include "cli/cell_plan_worker.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <thread>

#include "cell/jobs.hpp"
#include "cell/reconnecting.hpp"
#include "cell/schema.hpp"
#include "cli/commands.hpp"
#include "gcode/files.hpp"

namespace hybridctl::cli {
namespace {

namespace fs = std::filesystem;
using cell::Database;
using cell::DatabaseError;

void log(const std::string& worker, const std::string& text) {
  std::printf("plan-worker %s: %s\n", worker.c_str(), text.c_str());
  std::fflush(stdout);
}

// The worker's connection: LISTENs for submissions and outcomes, and logs its losses.
class Connection : public cell::Reconnecting {
 public:
  Connection(const std::string& uri, const std::string& worker)
      : Reconnecting(uri, {"cell_jobs", "cell_jobs_done"}, [worker](const std::string& text) { log(worker, text); }) {}
};

// A name the part can have on disk: its file name's letters, digits, dots, dashes.
std::string safe_file_name(const std::string& name, const std::string& fallback) {
  std::string out;
  for (char c : fs::path(name).filename().string())
    out += (std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '-' || c == '_') ? c : '_';
  if (out.empty() || out[0] == '.') out = fallback;
  return out;
}

// The child: this hybridctl's `plan`, its output into the job's log; it dies with the worker.
pid_t start_planning(const fs::path& dir, const cell::Claim& job, const fs::path& part, const fs::path& machine) {
  std::vector<std::string> args = {"/proc/self/exe", "plan", part.string(), "--machine", machine.string(),
                                   "-o", (dir / "plan").string(), "--report"};
  auto number = [](double x) {
    char text[64];
    std::snprintf(text, sizeof text, "%.17g", x);
    return std::string(text);
  };
  if (job.request.voxel) args.insert(args.end(), {"--voxel", number(*job.request.voxel)});
  if (job.request.tolerance) args.insert(args.end(), {"--tolerance", number(*job.request.tolerance)});
  if (job.request.top) args.insert(args.end(), {"--top", std::to_string(*job.request.top)});
  const std::string log_path = (dir / "plan.log").string();
  const pid_t parent = getpid();
  const pid_t child = fork();
  if (child < 0) throw std::runtime_error(std::string("cannot start the planning: ") + std::strerror(errno));
  if (child > 0) return child;
  prctl(PR_SET_PDEATHSIG, SIGKILL);
  if (getppid() != parent) _exit(127);  // the worker died before the line above
  const int out = open(log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (out >= 0) dup2(out, STDOUT_FILENO), dup2(out, STDERR_FILENO);
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  execv("/proc/self/exe", argv.data());
  _exit(127);
}

// The plan directory's files, by their path in it, and the child's log.
std::vector<std::pair<std::string, std::string>> plan_files(const fs::path& dir) {
  std::vector<std::pair<std::string, std::string>> files;
  std::error_code ec;
  if (fs::is_directory(dir / "plan", ec))
    for (const fs::directory_entry& e : fs::recursive_directory_iterator(dir / "plan"))
      if (e.is_regular_file()) files.emplace_back(fs::relative(e.path(), dir / "plan").string(), gcode::read_text_file(e.path()));
  files.emplace_back("plan.log", fs::exists(dir / "plan.log", ec) ? gcode::read_text_file(dir / "plan.log") : std::string());
  return files;
}

// What the log says of why: its verdict line for a part that cannot be made, its last
// lines otherwise.
std::string reason_from_log(const std::string& log_text, int code) {
  std::istringstream in(log_text);
  std::string line, verdict, last;
  while (std::getline(in, line)) {
    if (line.rfind("verdict", 0) == 0) verdict = line.substr(line.find_first_not_of(' ', 7));
    if (!line.empty()) last = line;
  }
  if (code == kNotManufacturable && !verdict.empty()) return verdict;
  return last.empty() ? "`plan` exited " + std::to_string(code) + " without a word" : last;
}

cell::Outcome outcome_of(int status, const fs::path& dir) {
  cell::Outcome out;
  out.files = plan_files(dir);
  const std::string& log_text = out.files.back().second;
  if (WIFSIGNALED(status)) {
    out.state = cell::JobState::Failed;
    out.reason = std::string("`plan` was killed by signal ") + strsignal(WTERMSIG(status)) + ": " + reason_from_log(log_text, 1);
    return out;
  }
  const int code = WEXITSTATUS(status);
  out.state = code == kSuccess ? cell::JobState::Planned : code == kNotManufacturable ? cell::JobState::Refused : cell::JobState::Failed;
  if (code != kSuccess) out.reason = reason_from_log(log_text, code);
  return out;
}

// Plans one claimed job; false when its lease was lost on the way (nothing stored).
bool plan_job(Connection& conn, const PlanWorkerOptions& o, const std::string& worker, const cell::Claim& job) {
  char pattern[] = "/tmp/hybridctl-cell-job-XXXXXX";
  if (!mkdtemp(pattern)) throw std::runtime_error(std::string("cannot make a job directory: ") + std::strerror(errno));
  const fs::path dir = pattern;
  struct Cleanup {
    fs::path dir;
    ~Cleanup() {
      std::error_code ec;
      fs::remove_all(dir, ec);
    }
  } cleanup{dir};
  const fs::path part = dir / safe_file_name(job.part_name, "part.stl");
  const fs::path machine = dir / (safe_file_name(job.machine, "machine") + ".yaml");
  std::ofstream(part, std::ios::binary) << job.part_stl;
  std::ofstream(machine, std::ios::binary) << job.machine_text;
  const pid_t child = start_planning(dir, job, part, machine);
  auto renewed = std::chrono::steady_clock::now();
  int status = 0;
  while (waitpid(child, &status, WNOHANG) == 0) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    if (std::chrono::steady_clock::now() - renewed < std::chrono::duration<double>(o.lease_s / 3)) continue;
    if (!conn.retrying([&](Database& db) { return cell::renew_lease(db, job.job, worker, o.lease_s); })) {
      kill(child, SIGKILL);
      waitpid(child, &status, 0);
      log(worker, "job " + std::to_string(job.job) + ": the lease is no longer ours; planning stopped, nothing stored");
      return false;
    }
    renewed = std::chrono::steady_clock::now();
  }
  const cell::Outcome outcome = outcome_of(status, dir);
  if (!conn.retrying([&](Database& db) { return cell::finish(db, job.job, worker, outcome); })) {
    log(worker, "job " + std::to_string(job.job) + ": the lease ran out before the result was stored; nothing stored");
    return false;
  }
  log(worker, "job " + std::to_string(job.job) + " (" + job.part_name + " on " + job.machine + "): " +
                  cell::state_name(outcome.state) + (outcome.reason.empty() ? "" : ": " + outcome.reason));
  return true;
}

std::string default_name() {
  char host[256] = {};
  gethostname(host, sizeof host - 1);
  return std::string(host) + ":" + std::to_string(getpid());
}

}  // namespace

int run_plan_worker(const PlanWorkerOptions& o) {
  const std::string worker = o.name.empty() ? default_name() : o.name;
  Connection conn(o.db, worker);
  cell::require_current_schema(conn.db());
  log(worker, "planning the jobs of " + cell::redacted(o.db) + " (lease " + std::to_string(int(o.lease_s)) + " s)");
  for (;;) {
    const std::optional<cell::Claim> job =
        conn.retrying([&](Database& db) { return cell::claim_next(db, worker, o.lease_s, o.max_attempts); });
    if (job) {
      log(worker, "job " + std::to_string(job->job) + ": " + job->part_name + " on " + job->machine + ", attempt " +
                      std::to_string(job->attempt));
      plan_job(conn, o, worker, *job);
      continue;
    }
    // Draining ends when nothing is queued and nothing is being planned: a job another
    // worker plans may still come back to the queue if that worker dies.
    if (o.drain && conn.retrying([](Database& db) {
          return db.exec("the jobs left", "SELECT count(*) FROM cell_jobs WHERE state IN ('queued', 'planning')").number(0, 0) == 0;
        })) {
      log(worker, "no job left");
      return kSuccess;
    }
    // Woken by a submission or an outcome, or every few seconds to take jobs whose lease ran out.
    conn.retrying([&](Database& db) { return db.wait_for_notification(int(std::min(5.0, o.lease_s) * 1000)); });
  }
}

}  // namespace hybridctl::cli
