#pragma once
// Streaming one program to a controller, exactly once (docs/protocol.md, "Host
// procedures"): set the program (or find it there and resume), keep the controller's
// buffer full from its free-space report with as many whole lines per chunk as fit, send
// each chunk and read the status in one request where the transport allows, keep the
// heartbeat, and follow the controller through stops, alarms, reconnects and reboots.
//
// The controller's status is the truth: the next chunk is always number
// last_accepted_chunk + 1 starting at next_line, so after a reconnect, a host restart or
// a controller reboot nothing is skipped and nothing runs twice.

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "protocol/messages.hpp"
#include "drivers/controller_loss.hpp"
#include "drivers/transport.hpp"

namespace hybridctl::drivers {

class JobRecord;

// What the streamer asks of its user when the program needs a decision.
struct StreamCallbacks {
  // Every status read (for a live status line).
  std::function<void(const protocol::Status&)> status;
  // Something worth a line in the log ("controller restarted: resuming at line 812").
  std::function<void(const std::string&)> note;
  // The program stopped at M0/M1 (the operator message is in the program text before
  // the line): true to continue (OPERATOR_ACK), false to stop streaming here.
  std::function<bool(const protocol::Status&)> program_stop;
  // An alarm the operator may clear (controller restarted, heartbeat lost): true to send
  // RESET_ALARM and RESUME. Alarms caused by the program itself always end the stream.
  std::function<bool(const protocol::Status&)> recover;
  // A warning the controller reports while it goes on (protocol::AlarmInfo::warning,
  // e.g. DEPOSITION_OVER_AIR), once per code and line seen; it is also noted.
  std::function<void(const protocol::Status&)> warning;
  // Polled between requests: true to hold (FEED_HOLD) — e.g. after Ctrl-C.
  std::function<bool()> hold_requested;
  // While held at the host's request: true to resume, false to abort.
  std::function<bool(const protocol::Status&)> resume_after_hold;
};

struct StreamOptions {
  double heartbeat_period_s = 0.2;  // the protocol asks for at most 0.25 s
  double poll_period_s = 0.002;     // status polling when there is nothing to send
  // Resume: the controller must hold this very program (its identity); never SET_PROGRAM.
  bool resume = false;
  // Without `resume`: resume all the same when the controller holds this very program (a
  // host died after it sent lines its record had not yet kept), else set it. Only for a
  // program whose identity is its job's alone (the cell's programs name their job).
  bool resume_when_ours = false;
  // Resume after the host held the feed itself (JournalProgress::held_by_host): RESUME
  // once the controller's buffer is refilled.
  bool resume_host_hold = false;
  // While the controller waits on someone (a feed hold at the machine), a note saying so
  // this often.
  double waiting_note_period_s = 5.0;
  // A request the transport gave up on (after its own resends) costs a pause (100 ms,
  // doubling up to 2 s) and a fresh status read; this many in a row with no progress in
  // between (no chunk taken, no line executed) end the stream (TransportError).
  int max_failures_in_row = 5;
  // A controller that stops answering at all once the stream is under way (a power cycle,
  // a reboot, a pulled cable) is waited for this long, reconnecting on the transport's
  // schedule and saying so, before the stream ends Unreachable: a controller that boots
  // again is met at its first status (docs/drivers.md). Before the first status:
  // Unreachable at once.
  double controller_back_within_s = 120.0;
};

struct StreamCounters {
  std::uint64_t chunks_sent = 0;     // chunk writes, all results
  std::uint64_t chunks_accepted = 0;
  std::uint64_t duplicates = 0;      // the controller already had it (a lost reply)
  std::uint64_t refused = 0;         // gap, line mismatch, buffer full ...: recomputed from the status
  std::uint64_t transport_errors = 0;  // requests the transport gave up on, recovered from here
  std::uint64_t reboots_seen = 0;
  std::uint64_t recoveries = 0;      // alarms cleared with RESET_ALARM + RESUME
  std::uint64_t warnings = 0;        // warnings seen (code and line changed), the program going on
};

struct StreamResult {
  bool completed = false;
  protocol::Status final_status;
  std::string stopped_because;  // when not completed: the alarm or the decision that ended it
  // The controller lost the program (docs/drivers.md "Controller power loss"): the
  // stream stopped at the first status that showed it; stopped_because says what to do.
  std::optional<ControllerLoss> loss;
  StreamCounters counters;
};

// Streams `lines` (the program as protocol::program_lines splits it). Throws
// TransportError when the controller cannot be reached any more (the journal lets a later
// run resume), InputError when the controller holds another program and `resume` asks
// for this one, or it is busy with another program.
StreamResult stream_program(Transport& transport, std::span<const std::string> lines, const StreamOptions& options,
                            const StreamCallbacks& callbacks, JobRecord* record = nullptr);

}  // namespace hybridctl::drivers
