#pragma once
// Where a streamed job's progress is kept, so that another host process can go on with it
// after this one died: a journal file in a job directory (drivers/journal.hpp, `hybridctl
// run`), or the shop cell's database (cell/stream_journal.hpp, `hybridctl cell
// machine-host`). The streamer records through this and nothing else. The controller's
// own status stays the truth for where to continue; the record says what to continue.

#include <cstdint>
#include <string>

namespace hybridctl::drivers {

struct JournalProgress {
  std::uint32_t last_chunk = 0;  // last acknowledged chunk
  std::uint32_t through_line = 0;
  std::uint32_t executed_line = 0;  // last executed line seen in a status
  bool completed = false;
  // The controller lost the program (docs/drivers.md "Controller power loss"): what it had
  // reported executed and accepted then.
  bool lost = false;
  std::uint32_t lost_executed_line = 0, lost_accepted_line = 0;
  // The host held the feed and stopped (the record could not be written): a resume
  // sends RESUME once the controller's buffer is refilled.
  bool held_by_host = false;
};

class JobRecord {
 public:
  virtual ~JobRecord() = default;
  virtual const JournalProgress& progress() const = 0;
  // An acknowledged chunk. Kept durable within a short period, not before the stream goes
  // on: the controller, not the record, says where to go on.
  virtual void acknowledged(std::uint32_t chunk, std::uint32_t through_line, std::uint32_t executed_line) = 0;
  // The last line the controller reports executed, at every status read of this program:
  // for people watching the job elsewhere; a record may keep it or leave it to the next
  // acknowledgement.
  virtual void executed(std::uint32_t /*line*/) {}
  // Free-form events (reconnects, reboots, alarms).
  virtual void note(const std::string& event) = 0;
  // Durable at once.
  virtual void completed(std::uint32_t executed_line) = 0;
  virtual void lost(const std::string& kind, const std::string& what, std::uint32_t executed_line, std::uint32_t accepted_line) = 0;
  virtual void held_by_host(const std::string& why) = 0;
  // Whether the record can still be kept; once false, the streamer sends nothing more,
  // holds the feed and stops (everything sent so far is recorded).
  virtual bool writable() const = 0;
  // Why it cannot, in words ("the journal F cannot be written (disk full)").
  virtual std::string why_unwritable() const = 0;
  // The command that goes on with this job ("hybridctl run --resume DIR"); a restart
  // after a controller loss appends " --from-line N".
  virtual std::string resume_command() const = 0;
  // What happens before that command, when the record could not be kept ("Free space").
  virtual std::string before_resuming() const = 0;
};

}  // namespace hybridctl::drivers
