// LinuxcncController::tick and what it does with LinuxCNC's status: the part of the
// bridge that follows LinuxCNC (the command side is linuxcnc_controller.cpp).

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <sys/stat.h>

#include "bridge/linuxcnc_controller.hpp"

namespace hybridctl::bridge {

using protocol::AlarmCode;
using protocol::ControllerState;

namespace {

bool program_running(ControllerState s) {
  return s == ControllerState::Running || s == ControllerState::FeedHold || s == ControllerState::ProgramStop ||
         s == ControllerState::OptionalStop;
}

}  // namespace

void LinuxcncController::tick(std::chrono::steady_clock::time_point now) {
  now_ = now;
  // The heartbeat first: the status read below may block (a loaded host), and the
  // heartbeats that arrive meanwhile are only read after this tick.
  if (state_ == ControllerState::Running && options_.heartbeat_timeout_s > 0 &&
      std::chrono::duration<double>(now_ - heartbeat_changed_).count() > options_.heartbeat_timeout_s) {
    if (segment_) {
      try {
        link_.pause();
      } catch (const LinkError& e) {
        if (options_.log) options_.log(std::string("feed hold: ") + e.what());
      }
    }
    raise(AlarmCode::HostHeartbeatLost, 0,
          "no heartbeat change for " + std::to_string(options_.heartbeat_timeout_s) + " s: LinuxCNC paused");
  }
  LinuxcncStatus s;
  try {
    s = link_.status();
  } catch (const LinkError& e) {
    s.connected = false;
    s.why = e.what();
  }
  if (!s.connected) {
    if (!linuxcnc_lost_) lost(s.why);
    last_ = std::move(s);
    return;
  }
  if (linuxcnc_lost_) back_after_loss();
  last_ = s;
  if (s.estop && program_running(state_) && started_) {
    stop_segment_on_alarm();
    prepared_ = false;
    raise(AlarmCode::EmergencyStop, last_executed_line_ + 1, "LinuxCNC is in e-stop");
  }
  take_messages(s);
  follow_segment(s);
  if (state_ == ControllerState::Running && !segment_) start_next_segment();
}

// LinuxCNC's error channel: an error while a segment runs stops the program (LinuxCNC
// aborted it); everything else goes to the log.
void LinuxcncController::take_messages(const LinuxcncStatus& s) {
  for (const LinuxcncMessage& m : s.messages) {
    if (options_.log) options_.log(std::string("LinuxCNC ") + (m.error ? "error: " : "message: ") + m.text);
    // "Note: ..." comes on the error channel but is a remark (e.g. after an e-stop reset).
    if (!m.error || m.text.rfind("Note:", 0) == 0 || !segment_ || state_ == ControllerState::Alarm) continue;
    fail_segment(m.text);
  }
}

void LinuxcncController::follow_segment(const LinuxcncStatus& s) {
  if (!segment_ || s.file != segment_path_) return;
  if (s.interp_state == LinuxcncStatus::kInterpIdle) {
    if (ended_normally(s)) {
      executed_through(segment_->last_line());
      segment_.reset();
      idle_early_since_.reset();
      return;
    }
    // Idle before the end: an e-stop, an error or an abort at the machine. Its e-stop
    // flag or error message may come a status or two later; without either, after a
    // second, it is an alarm of its own.
    if (!idle_early_since_) idle_early_since_ = now_;
    if (now_ - *idle_early_since_ > std::chrono::seconds(1)) {
      idle_early_since_.reset();
      fail_segment("LinuxCNC stopped the program at file line " + std::to_string(s.current_line) +
                   " of " + segment_path_ + " without an error (aborted at the machine?)");
    }
    return;
  }
  idle_early_since_.reset();
  const std::uint32_t moving = program_line(*segment_, s.motion_line);
  if (moving > 1) executed_through(moving - 1);
  if (s.paused && !hold_requested_ && state_ == ControllerState::Running) {
    // Not our feed hold: an M0/M1 line, or the operator's pause at the machine. At an
    // M0/M1 LinuxCNC shows the line of the last motion before it (checked on 2.9): the
    // stop is the first M0/M1 line after that one.
    int stop = -1;
    std::uint32_t at = std::max(program_line(*segment_, s.current_line), segment_->first_line);
    for (; at <= segment_->last_line(); ++at) {
      stop = stop_code(segment_->lines[at - segment_->first_line]);
      if (stop >= 0) break;
    }
    if (stop >= 0) {
      executed_through(at);
      state_ = stop == 0 ? ControllerState::ProgramStop : ControllerState::OptionalStop;
    } else {
      state_ = ControllerState::FeedHold;
    }
  }
}

// LinuxCNC ran the segment to its end: machine on, its interpreter at the file's last
// program line, or stopped by a program end (M2/M30). After an M2 LinuxCNC shows the
// line of the last motion before it (as at an M0, checked on 2.9), so the program end
// is the first M2/M30 after that line with no move in between.
bool LinuxcncController::ended_normally(const LinuxcncStatus& s) const {
  if (s.estop || s.task_state != LinuxcncStatus::kOn) return false;
  const std::uint32_t at = program_line(*segment_, s.current_line);
  if (at == 0) return false;
  if (at >= segment_->last_line()) return true;
  for (std::uint32_t n = at; n <= segment_->last_line(); ++n) {
    const std::string& text = segment_->lines[n - segment_->first_line];
    if (program_end(text)) return true;
    if (n > at && moves(text)) return false;
  }
  return false;
}

void LinuxcncController::executed_through(std::uint32_t line) {
  if (!segment_) return;
  line = std::min(line, segment_->last_line());
  for (std::uint32_t n = std::max(last_executed_line_ + 1, segment_->first_line); n <= line; ++n) {
    if (options_.on_line_executed) options_.on_line_executed(n, segment_->lines[n - segment_->first_line]);
    ++report_.lines_executed;
  }
  last_executed_line_ = std::max(last_executed_line_, line);
  while (!chunk_ends_.empty() && chunk_ends_.front().second <= last_executed_line_) {
    last_executed_chunk_ = chunk_ends_.front().first;
    chunk_ends_.erase(chunk_ends_.begin());
  }
  if (finished() && program_running(state_)) state_ = ControllerState::Completed;
}

void LinuxcncController::start_next_segment() {
  while (std::optional<protocol::Chunk> chunk = acceptor_.take()) {
    chunk_ends_.emplace_back(chunk->seq, chunk->first_line + chunk->line_count - 1);
    feeder_.add_lines(chunk->first_line, chunk->payload);
  }
  std::optional<Segment> next = feeder_.next_segment(acceptor_.line_count());
  if (!next) return;
  ++report_.segments;
  const std::filesystem::path path = std::filesystem::path(options_.segment_dir) /
                                     ("segment-" + std::to_string(boot_count_) + "-" + std::to_string(report_.segments) + ".ngc");
  {
    std::ofstream out(path.string() + ".tmp", std::ios::binary | std::ios::trunc);
    out << segment_file_text(*next);
    if (!out.flush()) {
      feeder_.requeue(*next, next->first_line);
      raise(AlarmCode::LinuxcncError, next->first_line, "cannot write the segment file " + path.string());
      return;
    }
  }
  chmod((path.string() + ".tmp").c_str(), 0644);  // LinuxCNC may run as another user
  std::filesystem::rename(path.string() + ".tmp", path);
  if (options_.log)
    options_.log("segment " + std::to_string(report_.segments) + ": lines " + std::to_string(next->first_line) + ".." +
                 std::to_string(next->last_line()) + " " + path.string());
  segment_ = std::move(next);
  segment_path_ = path.string();
  try {
    link_.run(segment_path_);
  } catch (const LinkError& e) {
    fail_segment(e.what());
  }
}

// LinuxCNC stopped the segment with an error: the alarm its text names, at the line it
// names ("... on line N ...", "... near line N ...": a line of the segment's file) or
// else the line after the last executed.
void LinuxcncController::fail_segment(const std::string& message) {
  std::uint32_t line = last_executed_line_ + 1;
  const std::size_t at = message.find("line ");
  if (segment_ && at != std::string::npos) {
    const int file_line = std::atoi(message.c_str() + at + 5);
    if (const std::uint32_t mapped = program_line(*segment_, file_line)) line = std::max(mapped, line);
  }
  stop_segment_on_alarm();
  raise(alarm_for_message(message), line, "LinuxCNC: " + message);
}

// The lines of the segment LinuxCNC did not execute go back to the feeder: a RESUME
// after RESET_ALARM runs them in a new segment.
void LinuxcncController::stop_segment_on_alarm() {
  idle_early_since_.reset();
  if (!segment_) return;
  feeder_.requeue(*segment_, last_executed_line_ + 1);
  segment_.reset();
}

void LinuxcncController::lost(const std::string& why) {
  linuxcnc_lost_ = true;
  prepared_ = false;
  segment_.reset();
  if (options_.log) options_.log("LinuxCNC lost: " + why);
  if (started_ && program_running(state_)) raise(AlarmCode::LinuxcncLost, 0, "LinuxCNC stopped answering: " + why);
}

// LinuxCNC came back (restarted): its program, position and modal state are gone, so the
// bridge counts a new boot without a program; the host sees a controller loss
// (drivers/controller_loss.hpp) and says which lines ran.
void LinuxcncController::back_after_loss() {
  linuxcnc_lost_ = false;
  ++boot_count_;
  ++report_.boots;
  if (options_.log) options_.log("LinuxCNC is back: boot " + std::to_string(boot_count_) + ", without the program");
  acceptor_ = protocol::ChunkAcceptor({options_.buffer_bytes, options_.max_chunk_payload});
  gate_ = protocol::CommandGate();
  feeder_.clear();
  chunk_ends_.clear();
  last_executed_chunk_ = last_executed_line_ = 0;
  started_ = aborted_ = hold_requested_ = false;
  alarm_ = AlarmCode::None;
  alarm_line_ = 0;
  state_ = ControllerState::Idle;
}

}  // namespace hybridctl::bridge
