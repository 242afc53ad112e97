#pragma once
// The job journal: an append-only file that lets `hybridctl run --resume JOB` continue a
// program after the host process died. One JSON object per line: a header (the program
// file, its identity and line count, machine file, transport), then the acknowledged
// progress (chunk, through which line), written as each range is acknowledged and synced
// to disk at most sync_period_s later by a background thread (the stream does not wait
// for the disk: an fsync takes milliseconds, a CAN bus idles meanwhile), the end of the
// job at once. The controller's own status stays the truth for where to continue; the
// journal says what to continue.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "drivers/job_record.hpp"

namespace hybridctl::drivers {

struct JournalHeader {
  std::string program;    // absolute path of the program streamed
  std::uint64_t identity = 0;
  std::uint32_t lines = 0;
  std::string machine;    // machine file
  std::string transport;  // URI
  std::string source;     // what the program was made from (plan.json and rank), for people
  // After `run --resume --from-line N`: the program above is the restart (a preamble, then
  // the original's lines N..end; docs/drivers.md "Controller power loss").
  std::uint32_t restart_from_line = 0;
  std::uint32_t restart_preamble_lines = 0;
  std::string original_program;  // the program the restart was made from
};

class Journal : public JobRecord {
 public:
  // Starts a new journal in `directory` (made if missing; an existing journal there is
  // refused: a job directory holds one job).
  static Journal create(const std::filesystem::path& directory, const JournalHeader& header);
  // Opens an existing one for appending, reading back its header and last progress.
  // Throws InputError naming the file and line of anything malformed.
  static Journal open(const std::filesystem::path& directory);

  Journal(Journal&&) noexcept;
  Journal& operator=(Journal&&) noexcept;
  ~Journal() override;

  const JournalHeader& header() const { return header_; }
  const JournalProgress& progress() const override { return progress_; }
  std::filesystem::path file() const { return path_; }

  // Records an acknowledged chunk. The file is synced in the background within
  // `sync_period_s` (and at once at the end): the controller, not the journal, says
  // where to go on.
  void acknowledged(std::uint32_t chunk, std::uint32_t through_line, std::uint32_t executed_line) override;
  double sync_period_s = 0.1;
  // Free-form events (reconnects, reboots, alarms), not fsync'd on their own.
  void note(const std::string& event) override;
  void completed(std::uint32_t executed_line) override;
  // The controller lost the program: synced at once.
  void lost(const std::string& kind, const std::string& what, std::uint32_t executed_line, std::uint32_t accepted_line) override;
  // The job goes on as a new program (`run --resume --from-line`): the header's program,
  // identity and line count become the restart's; synced at once.
  void restarted(const std::string& program, std::uint64_t identity, std::uint32_t lines, std::uint32_t from_line,
                 std::uint32_t preamble_lines, const std::string& original_program);
  // The host held the feed because it cannot record what it sends (the disk is full).
  void held_by_host(const std::string& why) override;
  // Whether the journal can still record: false after a write failed (ENOSPC). The entry
  // that failed was written after freeing the journal's reserve (journal.reserve, made
  // at create), so nothing sent goes unrecorded; the streamer then stops sending.
  bool writable() const override { return !write_failed_; }
  std::string why_unwritable() const override { return "the journal " + path_.string() + " cannot be written (disk full)"; }
  std::string resume_command() const override { return "hybridctl run --resume " + path_.parent_path().string(); }
  std::string before_resuming() const override { return "Free space"; }

 private:
  struct BackgroundSync;
  Journal(std::filesystem::path path, int fd, JournalHeader header, JournalProgress progress);
  void append(const std::string& line, bool sync);
  void close();

  std::filesystem::path path_;
  int fd_ = -1;
  double last_sync_ = 0;
  JournalHeader header_;
  JournalProgress progress_;
  std::unique_ptr<BackgroundSync> background_;  // made at the first acknowledged range
  bool write_failed_ = false;
  std::uint64_t bytes_written_ = 0;  // for the injected disk-full limit (journal.cpp)
};

}  // namespace hybridctl::drivers
