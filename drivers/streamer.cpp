#include "drivers/streamer.hpp"

#include <chrono>
#include <limits>
#include <thread>

#include "common/error.hpp"
#include "drivers/backoff.hpp"
#include "drivers/job_record.hpp"
#include "protocol/chunk.hpp"
#include "protocol/chunk_acceptor.hpp"

namespace hybridctl::drivers {
namespace {

using protocol::AlarmCode;
using protocol::CommandCode;
using protocol::ControllerState;
using protocol::ResultCode;
using Clock = std::chrono::steady_clock;

double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

std::string hex64(std::uint64_t v) {
  char buf[19];
  std::snprintf(buf, sizeof buf, "0x%016llx", static_cast<unsigned long long>(v));
  return buf;
}

// The pause after a request the transport gave up on: 100 ms, doubling up to 2 s; it
// starts again at 100 ms after progress. When to give up is the streamer's own rule
// (StreamOptions::max_failures_in_row), so the schedule itself never runs out.
Backoff link_failure_backoff() { return Backoff(std::chrono::milliseconds(100), std::numeric_limits<int>::max()); }

// Alarms the program itself caused: no operator action makes resuming right.
bool program_fault(AlarmCode a) {
  return a == AlarmCode::EnvelopeViolation || a == AlarmCode::RapidIntoMaterial || a == AlarmCode::DepositionWithoutHead ||
         a == AlarmCode::GcodeError || a == AlarmCode::SpindleDepositionConflict || a == AlarmCode::ProgramIdentityMismatch ||
         a == AlarmCode::NozzleCollision;
}

// Thrown from a status read that shows the controller lost the program; caught in run().
struct Lost {
  ControllerLoss loss;
};

class Session {
 public:
  Session(Transport& t, std::span<const std::string> lines, const StreamOptions& o, const StreamCallbacks& cb, JobRecord* r)
      : t_(t), lines_(lines), options_(o), cb_(cb), record_(r), identity_(protocol::program_identity(lines)) {}

  StreamResult run() {
    try {
      stream();
    } catch (const Lost& l) {
      result_.loss = l.loss;
      result_.stopped_because = describe_loss(l.loss, record_ ? record_->resume_command() : std::string());
      if (record_) record_->lost(std::string(to_string(l.loss.kind)), l.loss.what, l.loss.executed_line, l.loss.accepted_line);
    }
    result_.final_status = status_;
    // After a loss the new controller's status says nothing of this program's lines.
    if (result_.loss) result_.final_status.last_executed_line = result_.loss->executed_line;
    if (record_ && result_.completed) record_->completed(status_.last_executed_line);
    return result_;
  }

 private:
  void stream() {
    status_ = t_.read_status();
    boot_ = status_.boot_count;
    seq_ = status_.command_seq;
    open_program();
    last_heartbeat_ = Clock::now() - std::chrono::seconds(1);
    int failures_in_row = 0;  // transport failures with no progress in between
    std::uint64_t progress_at_failure = 0;
    Backoff pause = link_failure_backoff();
    bool reread = false;
    while (true) {
      try {
        if (reread) {
          seen(t_.read_status());
          reread = false;
        }
        heartbeat();
        fill();
        if (decide()) break;
      } catch (const TransportError& e) {
        // The transport gave up on one request after its own resends, but the controller
        // answered before: a bad spell on the line, not a lost controller. Pause, read
        // the status again, and let it say what to send (a chunk that arrived comes back
        // DUPLICATE). An unreachable controller, or one failing request after another,
        // ends the stream: the journal lets `run --resume` go on later.
        if (e.kind() == TransportError::Kind::Unreachable) {
          wait_for_controller(e);
          reread = true;
          continue;
        }
        const bool transient = e.kind() != TransportError::Kind::Unsupported;
        // Progress: chunks taken or lines executed since the last failure.
        const std::uint64_t progress = result_.counters.chunks_accepted + status_.last_executed_line;
        failures_in_row = progress != progress_at_failure ? 1 : failures_in_row + 1;
        if (progress != progress_at_failure) pause = link_failure_backoff();
        progress_at_failure = progress;
        if (!transient || failures_in_row > options_.max_failures_in_row) throw;
        ++result_.counters.transport_errors;
        note(std::string("the link failed (") + e.what() + "); reading the controller's status again");
        pause.wait_after_failure();
        reread = true;
      }
    }
  }

  // The controller stopped answering mid-stream. A power cycle takes a while: wait for it
  // (StreamOptions::controller_back_within_s) with a note every few seconds; the transport
  // reconnects on its own schedule at each status read. Then the status read that
  // succeeds decides (a new boot without our program is a loss, see seen()).
  void wait_for_controller(const TransportError& first) {
    const auto since_lost = Clock::now();
    auto noted = since_lost - std::chrono::hours(1);
    std::string last = first.what();
    while (true) {
      const double waited = since(since_lost);
      if (waited >= options_.controller_back_within_s)
        throw TransportError(TransportError::Kind::Unreachable,
                             last + " (waited " + std::to_string(int(waited)) + " s for the controller to come back)");
      if (since(noted) >= options_.waiting_note_period_s) {
        noted = Clock::now();
        note("the controller does not answer (" + last + "); waiting for it to come back, " +
             std::to_string(int(options_.controller_back_within_s - waited)) + " s more");
      }
      try {
        seen(t_.read_status());
        note("the controller answers again after " + std::to_string(int(since(since_lost))) + " s");
        return;
      } catch (const TransportError& e) {
        if (e.kind() == TransportError::Kind::Unsupported) throw;
        last = e.what();
        std::this_thread::sleep_for(std::chrono::milliseconds(200));
      }
    }
  }

  // What this host knows of the controller, from every status of our program.
  void know(const protocol::Status& s) {
    if (known_.identity == 0 || s.identity != known_.identity) {
      known_.boot = s.boot_count;
      return;
    }
    if (s.boot_count != known_.boot) known_.accepted_chunk = s.last_accepted_chunk;  // the queue went with the boot
    known_.boot = s.boot_count;
    known_.executed_line = std::max(known_.executed_line, s.last_executed_line);
    known_.accepted_chunk = std::max(known_.accepted_chunk, s.last_accepted_chunk);
    if (s.state != ControllerState::Idle) known_.started = true;
  }
  void program_is_ours() {
    known_.identity = identity_;
    known_.boot = status_.boot_count;
    known_.accepted_chunk = status_.last_accepted_chunk;
    known_.executed_line = std::max(known_.executed_line, status_.last_executed_line);
    if (status_.next_line > 0) known_.accepted_line = std::max(known_.accepted_line, status_.next_line - 1);
    known_.started = status_.state != ControllerState::Idle;
  }
  // Every few seconds while the controller waits on someone else: say what for.
  void say_what_we_wait_for() {
    std::string what;
    if (status_.state == ControllerState::FeedHold && !held_by_us_ && !host_hold_)
      what = "the controller is in FEED_HOLD, held at the machine after line " + std::to_string(status_.last_executed_line) +
             ": cycle start (RESUME) there goes on";
    if (what.empty()) {
      waiting_since_.reset();
      return;
    }
    const auto now = Clock::now();
    if (!waiting_since_) waiting_since_ = now - std::chrono::hours(1);
    if (std::chrono::duration<double>(now - *waiting_since_).count() < options_.waiting_note_period_s) return;
    waiting_since_ = now;
    note("waiting: " + what);
  }
  // The record could not be kept (the disk is full, the cell's database lost): send
  // nothing more, hold the feed where the machine is, and stop; the resume command goes on
  // once the record can be kept again.
  void stop_unrecorded() {
    command(CommandCode::FeedHold);
    record_->held_by_host(record_->why_unwritable());
    result_.stopped_because = record_->why_unwritable() + ": the feed is held after line " +
                              std::to_string(status_.last_executed_line) + "; every chunk sent is recorded through line " +
                              std::to_string(known_.accepted_line) + ". " + record_->before_resuming() + ", then " +
                              record_->resume_command();
  }

  void note(const std::string& s) {
    if (cb_.note) cb_.note(s);
    if (record_) record_->note(s);
  }
  // A warning is reported in the status while the controller goes on: said once per code
  // and line (polling sees the latest one only; the controller's own log has them all).
  void warned(const protocol::Status& s) {
    if (s.alarm == AlarmCode::None || !protocol::alarm_info(s.alarm).warning) return;
    if (s.alarm == warned_code_ && s.alarm_line == warned_line_) return;
    warned_code_ = s.alarm;
    warned_line_ = s.alarm_line;
    ++result_.counters.warnings;
    const auto& info = protocol::alarm_info(s.alarm);
    note("warning " + std::string(info.name) + " at line " + std::to_string(s.alarm_line) + ": " +
         std::string(info.meaning));
    if (cb_.warning) cb_.warning(s);
  }
  AlarmCode warned_code_ = AlarmCode::None;
  std::uint32_t warned_line_ = 0;
  void seen(const protocol::Status& s) {
    if (auto loss = detect_loss(known_, s, std::uint32_t(lines_.size()))) {
      status_ = s;
      throw Lost{*loss};
    }
    know(s);
    status_ = s;
    if (record_ && s.identity == identity_) record_->executed(s.last_executed_line);
    if (cb_.status) cb_.status(s);
    warned(s);
    if (s.boot_count != boot_) {
      boot_ = s.boot_count;
      ++result_.counters.reboots_seen;
      seq_ = s.command_seq;  // the controller forgot the last seq
      note("controller restarted (boot " + std::to_string(s.boot_count) + "): its buffer was lost; resending from line " +
           std::to_string(s.next_line) + " (the safe point after line " + std::to_string(s.last_executed_line) + ")");
    }
  }
  protocol::Status command(CommandCode code) {
    protocol::Command c{code, seq_ = protocol::next_command_seq(seq_), 0, 0};
    if (code == CommandCode::SetProgram) {
      c.identity = identity_;
      c.line_count = std::uint32_t(lines_.size());
    }
    seen(t_.send_command(c));
    // A reply lost on the way may leave the status behind the command: read until it shows.
    for (int i = 0; i < 50 && status_.command_seq != c.seq; ++i) seen(t_.read_status());
    if (status_.command_seq == c.seq && status_.command_result != ResultCode::Accepted)
      note(std::string(protocol::to_string(code)) + " refused: " + std::string(protocol::to_string(status_.command_result)));
    return status_;
  }

  void open_program() {
    const bool ours = status_.identity == identity_;
    const ControllerState st = status_.state;
    const bool free = st == ControllerState::Idle || st == ControllerState::Completed || st == ControllerState::Aborted;
    if (options_.resume || (options_.resume_when_ours && ours)) {
      if (status_.identity == 0 && record_ && record_->progress().through_line > 0) {
        // The record says lines went there; the controller has none of them.
        known_.executed_line = record_->progress().executed_line;
        known_.accepted_line = record_->progress().through_line;
        throw Lost{{ControllerLoss::Kind::NewBootWithoutProgram,
                    "the controller holds no program (boot " + std::to_string(status_.boot_count) + ", state " +
                        std::string(protocol::to_string(st)) + ") while the job's record has lines 1.." +
                        std::to_string(known_.accepted_line) + " accepted",
                    known_.executed_line, known_.accepted_line, std::uint32_t(lines_.size())}};
      }
      if (!ours)
        throw InputError("the controller holds program " + hex64(status_.identity) + ", not this job's " + hex64(identity_) +
                         ": refusing to resume into another program");
      note("resuming: the controller executed through line " + std::to_string(status_.last_executed_line) + " of " +
           std::to_string(lines_.size()) + ", state " + std::string(protocol::to_string(st)));
      started_ = st != ControllerState::Idle;
      held_by_us_ = options_.resume_host_hold && st == ControllerState::FeedHold;
      program_is_ours();
      return;
    }
    if (ours && !free) {
      // Our own program, interrupted (a host restart without --resume): carry on.
      note("the controller is already running this program: continuing at line " + std::to_string(status_.next_line));
      started_ = true;
      program_is_ours();
      return;
    }
    if (!free)
      throw InputError("the controller is busy with program " + hex64(status_.identity) + " (state " +
                       std::string(protocol::to_string(st)) + "): refusing to mix programs; wait for it or ABORT it");
    command(CommandCode::SetProgram);
    if (status_.identity != identity_)
      throw InputError("the controller did not take the program: " + std::string(protocol::to_string(status_.command_result)));
    program_is_ours();
  }

  void heartbeat() {
    if (since(last_heartbeat_) < options_.heartbeat_period_s) return;
    t_.send_heartbeat(++heartbeat_);
    last_heartbeat_ = Clock::now();
  }

  // Sends chunks while the controller has room; the status after each says what next.
  // At most kChunksPerRound, so heartbeats and hold requests are seen between rounds.
  static constexpr int kChunksPerRound = 64;
  void fill() {
    const std::size_t max = t_.max_chunk_payload();
    more_to_send_ = false;
    for (int sent = 0; sent < kChunksPerRound; ++sent) {
      if (status_.identity != identity_ || !protocol::accepts_chunks(status_.state)) return;
      const std::uint32_t line = status_.next_line;
      if (line == 0 || line > lines_.size()) return;
      // The transport's limit, the controller's advertised one, and its free space.
      std::size_t room = std::min<std::size_t>(max, status_.free_buffer_bytes);
      if (status_.max_chunk_payload > 0) room = std::min<std::size_t>(room, status_.max_chunk_payload);
      if (room < 2) return;
      auto chunk = protocol::make_chunk(lines_, line, status_.last_accepted_chunk + 1, identity_, room);
      if (!chunk.ok()) {
        // The next line does not fit in the free space yet (or at all: a program error).
        if (chunk.error().code == ResultCode::TooLong && room < max) return;
        throw InputError("line " + std::to_string(line) + ": " + chunk.error().message);
      }
      const protocol::Chunk& c = chunk.value();
      ++result_.counters.chunks_sent;
      seen(t_.send_chunk(c));
      const bool ours_written = status_.last_written_chunk == c.seq;
      const ResultCode r = ours_written ? status_.chunk_result : ResultCode::None;
      if (r == ResultCode::Accepted) {
        ++result_.counters.chunks_accepted;
        known_.accepted_line = c.first_line + c.line_count - 1;
        if (record_) record_->acknowledged(c.seq, c.first_line + c.line_count - 1, status_.last_executed_line);
        more_to_send_ = sent + 1 == kChunksPerRound;
        if (record_ && !record_->writable()) return;
      } else if (r == ResultCode::Duplicate) {
        ++result_.counters.duplicates;
      } else if (r == ResultCode::BufferFull) {
        return;
      } else {
        ++result_.counters.refused;
        // The status has the truth and the next round starts from it; a controller that
        // keeps refusing the same chunk for the same reason will not change its mind.
        if (c.seq == refused_seq_ && r == refused_result_) {
          if (++refusals_ >= 20)
            throw InputError("the controller keeps refusing chunk " + std::to_string(c.seq) + " (line " +
                             std::to_string(c.first_line) + "): " + std::string(protocol::to_string(r)) + ": " +
                             std::string(protocol::result_info(r).meaning));
        } else {
          refused_seq_ = c.seq;
          refused_result_ = r;
          refusals_ = 1;
        }
        return;
      }
    }
  }

  // Follows the controller's state; true when the stream is over.
  bool decide() {
    if (record_ && !record_->writable()) {
      stop_unrecorded();
      return true;
    }
    say_what_we_wait_for();
    if (status_.identity != identity_) {
      // The controller lost the program (a reboot without a started program): set it again.
      if (status_.identity == 0 && status_.state == ControllerState::Idle) {
        command(CommandCode::SetProgram);
        program_is_ours();
        return false;
      }
      result_.stopped_because = "the controller now holds another program (" + hex64(status_.identity) + ")";
      return true;
    }
    switch (status_.state) {
      case ControllerState::Completed:
        result_.completed = true;
        return true;
      case ControllerState::Aborted:
        result_.stopped_because = "the program was aborted";
        return true;
      case ControllerState::Idle:
        if (!started_ && status_.last_accepted_chunk > 0) {
          command(CommandCode::Start);
          started_ = true;
          return false;
        }
        break;
      case ControllerState::ProgramStop:
      case ControllerState::OptionalStop:
        if (cb_.program_stop && cb_.program_stop(status_)) {
          command(CommandCode::OperatorAck);
          return false;
        }
        result_.stopped_because = "stopped at the program stop after line " + std::to_string(status_.last_executed_line);
        return true;
      case ControllerState::Alarm: {
        const AlarmCode a = status_.alarm;
        const auto& info = protocol::alarm_info(a);
        if (!program_fault(a) && cb_.recover && cb_.recover(status_)) {
          ++result_.counters.recoveries;
          note(std::string("alarm ") + std::string(info.name) + ": clearing it (RESET_ALARM) and resuming");
          command(CommandCode::ResetAlarm);
          held_by_us_ = true;
          return false;
        }
        result_.stopped_because = std::string("alarm ") + std::string(info.name) +
                                  (status_.alarm_line ? " at line " + std::to_string(status_.alarm_line) : std::string()) +
                                  ": " + std::string(info.meaning) + " " + std::string(info.action);
        return true;
      }
      case ControllerState::FeedHold:
        if (held_by_us_) {
          // After RESET_ALARM: once the buffer is refilled from the safe point, go on.
          if (status_.last_accepted_chunk > status_.last_executed_chunk || status_.next_line > lines_.size()) {
            command(CommandCode::Resume);
            held_by_us_ = false;
          }
          return false;
        }
        if (host_hold_) {
          if (cb_.resume_after_hold && cb_.resume_after_hold(status_)) {
            command(CommandCode::Resume);
            host_hold_ = false;
          } else {
            command(CommandCode::Abort);
          }
          return false;
        }
        break;
      case ControllerState::Running:
        if (cb_.hold_requested && cb_.hold_requested()) {
          command(CommandCode::FeedHold);
          host_hold_ = true;
          return false;
        }
        break;
    }
    // The round ended at its cap with chunks still going in: the status after the last one
    // is fresh, go on sending (a status read could wait a whole CAN status period).
    if (more_to_send_) return false;
    // Nothing to do but wait: read the status again.
    const bool room = status_.next_line <= lines_.size() && status_.free_buffer_bytes >= t_.max_chunk_payload();
    if (!room) std::this_thread::sleep_for(std::chrono::duration<double>(options_.poll_period_s));
    seen(t_.read_status());
    return false;
  }

  Transport& t_;
  std::span<const std::string> lines_;
  const StreamOptions& options_;
  const StreamCallbacks& cb_;
  JobRecord* record_;
  std::uint64_t identity_;
  protocol::Status status_;
  std::uint16_t boot_ = 0, seq_ = 0, heartbeat_ = 0;
  Clock::time_point last_heartbeat_;
  bool started_ = false, held_by_us_ = false, host_hold_ = false;
  bool more_to_send_ = false;  // fill() stopped at its cap, not for want of room
  std::uint32_t refused_seq_ = 0;
  ResultCode refused_result_ = ResultCode::None;
  int refusals_ = 0;
  StreamResult result_;
  StreamKnowledge known_;
  std::optional<Clock::time_point> waiting_since_;
};

}  // namespace

StreamResult stream_program(Transport& transport, std::span<const std::string> lines, const StreamOptions& options,
                            const StreamCallbacks& callbacks, JobRecord* journal) {
  if (lines.empty()) throw InputError("the program is empty: nothing to stream");
  Session session(transport, lines, options, callbacks, journal);
  return session.run();
}

}  // namespace hybridctl::drivers
