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

namespace hybridctl::drivers {

struct JournalHeader {
  std::string program;    // absolute path of the program streamed
  std::uint64_t identity = 0;
  std::uint32_t lines = 0;
  std::string machine;    // machine file
  std::string transport;  // URI
  std::string source;     // what the program was made from (plan.json and rank), for people
};

struct JournalProgress {
  std::uint32_t last_chunk = 0;  // last acknowledged chunk
  std::uint32_t through_line = 0;
  std::uint32_t executed_line = 0;  // last executed line seen in a status
  bool completed = false;
};

class Journal {
 public:
  // Starts a new journal in `directory` (made if missing; an existing journal there is
  // refused: a job directory holds one job).
  static Journal create(const std::filesystem::path& directory, const JournalHeader& header);
  // Opens an existing one for appending, reading back its header and last progress.
  // Throws InputError naming the file and line of anything malformed.
  static Journal open(const std::filesystem::path& directory);

  Journal(Journal&&) noexcept;
  Journal& operator=(Journal&&) noexcept;
  ~Journal();

  const JournalHeader& header() const { return header_; }
  const JournalProgress& progress() const { return progress_; }
  std::filesystem::path file() const { return path_; }

  // Records an acknowledged chunk. The file is synced in the background within
  // `sync_period_s` (and at once at the end): the controller, not the journal, says
  // where to go on.
  void acknowledged(std::uint32_t chunk, std::uint32_t through_line, std::uint32_t executed_line);
  double sync_period_s = 0.1;
  // Free-form events (reconnects, reboots, alarms), not fsync'd on their own.
  void note(const std::string& event);
  void completed(std::uint32_t executed_line);

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
};

}  // namespace hybridctl::drivers
