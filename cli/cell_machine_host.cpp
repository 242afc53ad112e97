#include "cli/cell_machine_host.hpp"

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <mutex>
#include <optional>
#include <thread>

#include "cell/jobs.hpp"
#include "cell/reconnecting.hpp"
#include "cell/schema.hpp"
#include "cell/stream_journal.hpp"
#include "cell/streams.hpp"
#include "cli/commands.hpp"
#include "cli/run_job.hpp"
#include "common/error.hpp"
#include "config/machine_loader.hpp"
#include "drivers/executor.hpp"
#include "drivers/job_restart.hpp"
#include "drivers/transport.hpp"
#include "plan/plan_file.hpp"
#include "plan/plan_machine.hpp"
#include "protocol/chunk.hpp"
#include "validation/execution.hpp"

namespace hybridctl::cli {
namespace {

using cell::Database;

void log(const std::string& host, const std::string& text) {
  std::printf("machine-host %s: %s\n", host.c_str(), text.c_str());
  std::fflush(stdout);
}

std::string default_name() {
  char host[256] = {};
  gethostname(host, sizeof host - 1);
  return std::string(host) + ":" + std::to_string(getpid());
}

// Renews the host's lease on the machine on a connection of its own, also while a plan is
// proven or nothing is to be done; says when another host took it.
class LeaseKeeper {
 public:
  LeaseKeeper(const MachineHostOptions& o, std::string host) : o_(o), host_(std::move(host)) {
    thread_ = std::thread([this] { run(); });
  }
  ~LeaseKeeper() {
    {
      std::lock_guard lock(mutex_);
      stop_ = true;
    }
    wake_.notify_one();
    thread_.join();
  }
  bool lost() const { return lost_; }

 private:
  void run() {
    std::unique_ptr<Database> db;
    std::unique_lock lock(mutex_);
    while (!stop_ && !lost_) {
      wake_.wait_for(lock, std::chrono::duration<double>(o_.lease_s / 4), [this] { return stop_; });
      if (stop_) break;
      lock.unlock();
      try {
        if (!db) db = std::make_unique<Database>(o_.db);
        if (!cell::renew_machine(*db, o_.machine, host_, o_.lease_s)) lost_ = true;
      } catch (const cell::DatabaseError&) {
        db.reset();  // tried again at the next period; the stream's record says when too long
      }
      lock.lock();
    }
  }

  const MachineHostOptions& o_;
  std::string host_;
  std::atomic<bool> lost_{false};
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  std::thread thread_;
};

// A directory of the host's own under /tmp, removed with everything in it.
struct TemporaryDirectory {
  std::filesystem::path path;
  TemporaryDirectory() {
    char pattern[] = "/tmp/hybridctl-cell-stream-XXXXXX";
    if (!mkdtemp(pattern)) throw std::runtime_error(std::string("cannot make a directory under /tmp: ") + std::strerror(errno));
    path = pattern;
  }
  ~TemporaryDirectory() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
};

class Host {
 public:
  explicit Host(const MachineHostOptions& o)
      : o_(o), name_(o.name.empty() ? default_name() : o.name),
        conn_(o.db, {"cell_jobs_done"}, [this](const std::string& text) { log(name_, text); }) {}

  int run() {
    cell::require_current_schema(conn_.db());
    const cell::MachineLease lease = take_the_machine();
    transport_ = o_.transport.empty() ? lease.transport : o_.transport;
    if (transport_.empty()) {
      conn_.retrying([&](Database& db) { cell::release_machine(db, o_.machine, name_); });
      throw InputError("machine " + o_.machine + " has no controller registered: `hybridctl cell machines add " + o_.machine +
                       " --machine FILE --transport URI`, or --transport URI");
    }
    LeaseKeeper keeper(o_, name_);
    // However the host ends (drained, stopped, refused), the next host need not wait for
    // the lease to run out; a job bound to the machine stays bound.
    struct Release {
      Host& host;
      ~Release() {
        try {
          cell::release_machine(host.conn_.db(), host.o_.machine, host.name_);
        } catch (const cell::DatabaseError&) {  // the lease runs out by itself
        }
      }
    } release{*this};
    log(name_, "driving machine " + o_.machine + " via " + transport_ + " (lease " + std::to_string(int(o_.lease_s)) + " s)");
    return serve(keeper);
  }

 private:
  // The machine's lease: a host that holds it is waited for, until it gives it up or its
  // lease runs out (it died).
  cell::MachineLease take_the_machine() {
    std::string waiting_for;
    for (;;) {
      cell::MachineLease lease = conn_.retrying([&](Database& db) { return cell::take_machine(db, o_.machine, name_, o_.lease_s); });
      if (lease.ours) return lease;
      if (lease.holder != waiting_for) {
        waiting_for = lease.holder;
        char left[32];
        std::snprintf(left, sizeof left, "%.0f", lease.seconds_left);
        log(name_, "machine " + o_.machine + " is driven by host " + lease.holder + " (its lease runs out in " + left +
                       " s unless renewed): waiting");
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(500));
    }
  }

  int serve(const LeaseKeeper& keeper) {
    bool restart_asked = o_.from_line > 0;
    for (;;) {
      if (keeper.lost()) throw InputError("machine " + o_.machine + ": another host took the machine's lease");
      if (std::optional<cell::BoundJob> bound = conn_.retrying([&](Database& db) { return cell::bound_job(db, o_.machine); })) {
        const bool restart = restart_asked;
        restart_asked = false;
        if (restart) restart_program(*bound);
        const int code = stream(*bound, !restart && bound->progress.through_line > 0);
        if (code != kSuccess) return code;
        continue;
      }
      if (restart_asked) throw InputError("--from-line: machine " + o_.machine + " has no job bound to it to restart");
      const std::optional<cell::PlannedJob> planned =
          conn_.retrying([&](Database& db) { return cell::next_planned(db, o_.machine); });
      if (!planned) {
        if (o_.drain) {
          log(name_, "no planned job left for machine " + o_.machine);
          return kSuccess;
        }
        conn_.retrying([&](Database& db) { return db.wait_for_notification(1000); });
        continue;
      }
      if (!confirmed(*planned)) return kSuccess;
      bind(*planned);
    }
  }

  bool confirmed(const cell::PlannedJob& job) {
    if (o_.yes) return true;
    const std::string what = "job " + std::to_string(job.job) + " (" + job.part_name + ", plan " + std::to_string(o_.plan_rank) + ")";
    if (::isatty(STDIN_FILENO) != 1)
      throw InputError(what + " is ready for machine " + o_.machine +
                       ": the operator confirms it at a terminal, or the host runs unattended with --yes");
    if (ask_at_terminal("Stream " + what + " to machine " + o_.machine + " now? The stock must be on the table")) return true;
    log(name_, what + " left planned: the operator declined");
    return false;
  }

  // The job's program, made as `run` makes a plan's (exported, executed on the simulated
  // machine from the raw stock, refused unless it makes the part), stored, and the job
  // bound to the machine.
  void bind(const cell::PlannedJob& job) {
    const std::string whose = "cell job " + std::to_string(job.job);
    std::string program;
    try {
      const auto files = conn_.retrying([&](Database& db) { return cell::job_files(db, job.job); });
      const TemporaryDirectory dir;
      cell::write_job_files(files, dir.path, whose);
      const plan::PlanFile file = plan::read_plan_file(dir.path);
      if (o_.plan_rank > int(file.plans.size()))
        throw InputError("--plan " + std::to_string(o_.plan_rank) + ": " + whose + " has " + std::to_string(file.plans.size()) + " plans");
      const plan::PlanFilePlan& plan = file.plans[std::size_t(o_.plan_rank - 1)];
      const plan::PlanMachine machine = plan::plan_machine(file, {});
      validation::ExecutionOptions options;
      options.export_options.post.program_name =
          "job-" + std::to_string(job.job) + " plan-" + std::to_string(o_.plan_rank) + " " + plan.expression;
      program = validation::require_proven(file, plan, machine.machine, options,
                                           "plan " + std::to_string(plan.rank) + " (" + plan.expression + ")")
                    .program.text();
    } catch (const cell::DatabaseError&) {
      throw;
    } catch (const std::exception& e) {  // InputError, NotManufacturableError: this job's, not the host's
      log(name_, whose + " failed: " + e.what());
      conn_.retrying([&](Database& db) { cell::fail_planned_job(db, job.job, name_, e.what()); });
      return;
    }
    if (conn_.retrying([&](Database& db) { return cell::bind_job(db, job.job, o_.machine, name_, o_.plan_rank, program); }))
      log(name_, "job " + std::to_string(job.job) + " (" + job.part_name + ") bound to machine " + o_.machine);
  }

  // After a controller loss: the bound job goes on as a restart of its original program.
  void restart_program(cell::BoundJob& job) {
    const config::Machine machine = config::parse_machine(job.machine_text, "cell job " + std::to_string(job.job) + " machine");
    const gcode::RestartProgram restart =
        drivers::restart_for(protocol::program_lines(job.original), job.restart_from_line, job.restart_preamble_lines,
                             job.progress, machine, o_.from_line);
    const std::string text = protocol::program_text(restart.lines);
    if (!conn_.retrying([&](Database& db) {
          return cell::restart_bound_job(db, job.job, o_.machine, name_, text, o_.from_line, restart.preamble_lines);
        }))
      throw InputError("machine " + o_.machine + ": another host took the machine's lease");
    job.program = text;
    job.progress = {};
    log(name_, "job " + std::to_string(job.job) + ": restarted at line " + std::to_string(o_.from_line) + " of its program");
  }

  int stream(const cell::BoundJob& job, bool resume) {
    const std::string name = "cell job " + std::to_string(job.job);
    if (job.host != name_)
      log(name_, name + ": resuming (last streamed by " + job.host + ", lines through " + std::to_string(job.progress.through_line) +
                     " acknowledged)");
    drivers::JobResult result;
    try {
      cell::StreamJournal journal({o_.db, job.job, o_.machine, name_, o_.lease_s, [this](const std::string& text) { log(name_, text); }},
                                  job.progress);
      drivers::RecordedJob recorded;
      recorded.machine = config::parse_machine(job.machine_text, name + " machine");
      recorded.program_text = job.program;
      recorded.program_name = name + " (" + job.part_name + ")";
      recorded.name = name;
      recorded.transport = transport_;
      recorded.record = &journal;
      recorded.resume = resume;
      recorded.wait_for_controller_s = o_.wait_for_controller_s;
      result = run_recorded_job(recorded, o_.yes);
    } catch (const drivers::TransportError& e) {  // the controller unreachable: exit 6, the job stays bound
      conn_.retrying([&](Database& db) { cell::stopped_on_machine(db, job.job, name_, e.what()); });
      throw;
    } catch (const InputError& e) {  // the controller holds another program, ...: exit 3, the job stays bound
      conn_.retrying([&](Database& db) { cell::stopped_on_machine(db, job.job, name_, e.what()); });
      throw;
    }
    if (result.stream.completed) {
      log(name_, name + " done on machine " + o_.machine);
      return kSuccess;
    }
    conn_.retrying([&](Database& db) { cell::stopped_on_machine(db, job.job, name_, result.stream.stopped_because); });
    log(name_, name + " stopped on machine " + o_.machine + "; it stays bound to it");
    return kMachineStopped;
  }

  const MachineHostOptions& o_;
  std::string name_;
  cell::Reconnecting conn_;
  std::string transport_;
};

}  // namespace

int run_machine_host(const MachineHostOptions& o) { return Host(o).run(); }

}  // namespace hybridctl::cli
