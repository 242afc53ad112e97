#pragma once
// A bound job's record in the cell's database (docs/cell.md, "Machine hosts"): what the
// streamer acknowledges is written to the job's cell_streams row, with its notes as
// events, by a thread of its own at most `sync_period_s` later (and a quarter of the lease
// apart when nothing changes), in one transaction that first renews the host's lease on
// the machine; a host whose lease another host took
// writes nothing more and stops sending (writable() turns false). The end of the job, a
// controller loss and a hold are written at once. The database unreachable for longer
// than half the lease also stops the stream: by then another host may take the machine.

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "drivers/job_record.hpp"

namespace hybridctl::cell {

class Database;

class StreamJournal : public drivers::JobRecord {
 public:
  struct Where {
    std::string uri;      // the cell's database
    std::int64_t job = 0;
    std::string machine;  // its name in the cell
    std::string host;     // the host process streaming it
    double lease_s = 30;  // of the host's lease on the machine
    std::function<void(const std::string&)> log;  // hears when the database goes and comes back
  };
  // Connects (throws DatabaseError when the database cannot be reached), starting from
  // what the job's row says.
  StreamJournal(Where where, drivers::JournalProgress start);
  ~StreamJournal() override;
  StreamJournal(const StreamJournal&) = delete;
  StreamJournal& operator=(const StreamJournal&) = delete;

  const drivers::JournalProgress& progress() const override { return progress_; }
  void acknowledged(std::uint32_t chunk, std::uint32_t through_line, std::uint32_t executed_line) override;
  void executed(std::uint32_t line) override;
  void note(const std::string& event) override;
  void completed(std::uint32_t executed_line) override;
  void lost(const std::string& kind, const std::string& what, std::uint32_t executed_line, std::uint32_t accepted_line) override;
  void held_by_host(const std::string& why) override;
  bool writable() const override;
  std::string why_unwritable() const override;
  std::string resume_command() const override;
  std::string before_resuming() const override;

  double sync_period_s = 0.1;

 private:
  struct Pending {
    drivers::JournalProgress progress;
    std::vector<std::pair<std::string, std::string>> events;  // event, detail
    bool done = false;
  };
  void run_writer();
  // Writes what is pending; false when it could not (the database, or the lease lost).
  bool write_pending();
  // Writes at once, waiting while the database is away (at most half the lease).
  void write_now();
  double seconds_since_written() const;

  Where where_;
  drivers::JournalProgress progress_;  // the streamer's thread's view
  mutable std::mutex mutex_;           // pending_, stop_, database_error_
  Pending pending_;
  bool changed_ = false;  // pending_ holds what is not yet written
  bool stop_ = false;
  std::condition_variable wake_;
  std::mutex db_mutex_;  // the connection, used by one thread at a time
  std::unique_ptr<Database> db_;
  std::atomic<double> last_written_s_;
  std::atomic<bool> lease_lost_{false};
  std::string database_error_;  // the last one, under mutex_; empty while writes succeed
  std::thread writer_;
};

}  // namespace hybridctl::cell
