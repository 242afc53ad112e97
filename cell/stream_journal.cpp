#include "cell/stream_journal.hpp"

#include <chrono>

#include "cell/database.hpp"
#include "cell/streams.hpp"

namespace hybridctl::cell {
namespace {

double seconds_now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

StreamJournal::StreamJournal(Where where, drivers::JournalProgress start)
    : where_(std::move(where)), progress_(start), db_(std::make_unique<Database>(where_.uri)), last_written_s_(seconds_now()) {
  pending_.progress = start;
  writer_ = std::thread([this] { run_writer(); });
}

StreamJournal::~StreamJournal() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_one();
  writer_.join();
  write_pending();  // the last acknowledgements and notes
}

void StreamJournal::acknowledged(std::uint32_t chunk, std::uint32_t through_line, std::uint32_t executed_line) {
  progress_.last_chunk = chunk;
  progress_.through_line = through_line;
  progress_.executed_line = executed_line;
  std::lock_guard lock(mutex_);
  pending_.progress = progress_;
  changed_ = true;
}

void StreamJournal::executed(std::uint32_t line) {
  if (line == progress_.executed_line) return;
  progress_.executed_line = line;
  std::lock_guard lock(mutex_);
  pending_.progress = progress_;
  changed_ = true;
}

void StreamJournal::note(const std::string& event) {
  std::lock_guard lock(mutex_);
  pending_.events.emplace_back("note", event);
  changed_ = true;
}

void StreamJournal::completed(std::uint32_t executed_line) {
  progress_.completed = true;
  progress_.executed_line = executed_line;
  {
    std::lock_guard lock(mutex_);
    pending_.progress = progress_;
    pending_.done = true;
    pending_.events.emplace_back("done", "all " + std::to_string(executed_line) + " lines executed");
  }
  write_now();
}

void StreamJournal::lost(const std::string& kind, const std::string& what, std::uint32_t executed_line, std::uint32_t accepted_line) {
  progress_.lost = true;
  progress_.lost_executed_line = executed_line;
  progress_.lost_accepted_line = accepted_line;
  {
    std::lock_guard lock(mutex_);
    pending_.progress = progress_;
    pending_.events.emplace_back("controller-lost", kind + ": " + what);
  }
  write_now();
}

void StreamJournal::held_by_host(const std::string& why) {
  progress_.held_by_host = true;
  {
    std::lock_guard lock(mutex_);
    pending_.progress = progress_;
    pending_.events.emplace_back("held-by-host", why);
  }
  write_now();
}

double StreamJournal::seconds_since_written() const { return seconds_now() - last_written_s_.load(); }

bool StreamJournal::writable() const { return !lease_lost_ && seconds_since_written() < where_.lease_s / 2; }

std::string StreamJournal::why_unwritable() const {
  if (lease_lost_) return "the host's lease on machine " + where_.machine + " was taken by another host";
  std::lock_guard lock(mutex_);
  return "the cell's database has not recorded job " + std::to_string(where_.job) + " for " +
         std::to_string(int(seconds_since_written())) + " s (" + (database_error_.empty() ? "no answer" : database_error_) +
         "): another host may take machine " + where_.machine + " when the lease runs out";
}

std::string StreamJournal::resume_command() const { return "hybridctl cell machine-host --machine " + where_.machine; }

std::string StreamJournal::before_resuming() const {
  return lease_lost_ ? "Let the host that holds the machine go on" : "Bring the database back";
}

void StreamJournal::run_writer() {
  std::unique_lock lock(mutex_);
  while (!stop_) {
    wake_.wait_for(lock, std::chrono::duration<double>(sync_period_s), [this] { return stop_; });
    if (stop_) break;
    // Nothing new is written a quarter lease apart: the write renews the lease.
    if (!changed_ && seconds_since_written() < where_.lease_s / 4) continue;
    lock.unlock();
    write_pending();
    lock.lock();
  }
}

bool StreamJournal::write_pending() {
  std::lock_guard db_lock(db_mutex_);
  if (lease_lost_) return false;
  Pending p;
  {
    std::lock_guard lock(mutex_);
    p = pending_;
    changed_ = false;
  }
  try {
    if (!db_) db_ = std::make_unique<Database>(where_.uri);
    const bool ours = db_->transaction([&] {
      if (!renew_machine(*db_, where_.machine, where_.host, where_.lease_s)) return false;
      const drivers::JournalProgress& g = p.progress;
      db_->exec("the job's progress",
                "UPDATE cell_streams SET last_chunk = $2, through_line = $3, executed_line = $4, completed = $5, lost = $6, "
                "lost_executed_line = $7, lost_accepted_line = $8, held_by_host = $9, host = $10, updated_at = now() "
                "WHERE job = $1",
                {Param::number(where_.job), Param::number(g.last_chunk), Param::number(g.through_line),
                 Param::number(g.executed_line), Param::text(g.completed ? "t" : "f"), Param::text(g.lost ? "t" : "f"),
                 Param::number(g.lost_executed_line), Param::number(g.lost_accepted_line),
                 Param::text(g.held_by_host ? "t" : "f"), Param::text(where_.host)});
      for (const auto& [event, detail] : p.events)
        db_->exec("the job's event", "INSERT INTO cell_job_events (job, worker, event, detail) VALUES ($1, $2, $3, $4)",
                  {Param::number(where_.job), Param::text(where_.host), Param::text(event), Param::text(detail)});
      if (p.done) {
        db_->exec("the job's end",
                  "UPDATE cell_jobs SET state = 'done', reason = NULL, finished_at = now() WHERE id = $1 AND state = 'streaming'",
                  {Param::number(where_.job)});
        db_->exec("the watchers' wake-up", "NOTIFY cell_jobs_done");
      }
      return true;
    });
    if (!ours) {
      lease_lost_ = true;
      return false;
    }
  } catch (const DatabaseError& e) {
    if (e.connection_lost()) db_.reset();
    std::lock_guard lock(mutex_);
    changed_ = true;  // written again at the next period
    if (database_error_.empty() && where_.log)
      where_.log(std::string("database lost (") + e.what() + "): the stream goes on while the lease lasts; its record waits");
    database_error_ = e.what();
    return false;
  }
  last_written_s_ = seconds_now();
  std::lock_guard lock(mutex_);
  if (!database_error_.empty() && where_.log) where_.log("database back: the job's record is written again");
  database_error_.clear();
  // The events written leave the queue; any that came meanwhile stay.
  pending_.events.erase(pending_.events.begin(), pending_.events.begin() + std::ptrdiff_t(p.events.size()));
  return true;
}

void StreamJournal::write_now() {
  while (!write_pending() && !lease_lost_ && seconds_since_written() < where_.lease_s / 2)
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
}

}  // namespace hybridctl::cell
