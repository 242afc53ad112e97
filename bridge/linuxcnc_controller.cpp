#include "bridge/linuxcnc_controller.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "common/error.hpp"

namespace hybridctl::bridge {

using protocol::AlarmCode;
using protocol::CommandCode;
using protocol::ControllerState;
using protocol::ResultCode;

namespace {

bool contains(std::string_view text, std::string_view part) {
  auto lower = [](std::string_view s) {
    std::string out(s);
    std::transform(out.begin(), out.end(), out.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return out;
  };
  return lower(text).find(lower(part)) != std::string::npos;
}

std::int32_t micrometres(double mm) {
  return std::int32_t(std::clamp(std::llround(mm * 1000.0), -2147483647LL, 2147483647LL));
}

}  // namespace

AlarmCode alarm_for_message(std::string_view text) {
  if (contains(text, "limit")) return AlarmCode::EnvelopeViolation;
  if (contains(text, "tool") && (contains(text, "not found") || contains(text, "not in") || contains(text, "invalid")))
    return AlarmCode::ToolNotInMagazine;
  if (contains(text, "near line") || contains(text, "g code") || contains(text, "m code") || contains(text, "word") ||
      contains(text, "bad character") || contains(text, "unknown"))
    return AlarmCode::GcodeError;
  return AlarmCode::LinuxcncError;
}

LinuxcncController::LinuxcncController(LinuxcncLink& link, ControllerOptions options)
    : link_(link), options_(std::move(options)), acceptor_({options_.buffer_bytes, options_.max_chunk_payload}) {}

protocol::ChunkVerdict LinuxcncController::write_mailbox(std::span<const std::uint16_t> registers) {
  protocol::ChunkVerdict v = acceptor_.offer_mailbox(registers, state_);
  if (v.result == ResultCode::IdentityMismatch && state_ == ControllerState::Running)
    raise(AlarmCode::ProgramIdentityMismatch, 0, v.message);
  return v;
}

protocol::ChunkVerdict LinuxcncController::write_message(std::span<const std::uint8_t> message) {
  protocol::ChunkVerdict v = acceptor_.offer_message(message, state_);
  if (v.result == ResultCode::IdentityMismatch && state_ == ControllerState::Running)
    raise(AlarmCode::ProgramIdentityMismatch, 0, v.message);
  return v;
}

protocol::ResultCode LinuxcncController::write_command(std::span<const std::uint16_t> registers) {
  const auto intake = gate_.offer(registers);
  if (intake.decision != protocol::CommandGate::Decision::Execute)
    return intake.decision == protocol::CommandGate::Decision::Refused ? intake.error.code : gate_.last_result();
  const ResultCode r = command(intake.command);
  gate_.record(r);
  return r;
}

protocol::ResultCode LinuxcncController::write_command(const protocol::Command& c) {
  const auto intake = gate_.offer(c);
  if (intake.decision != protocol::CommandGate::Decision::Execute)
    return intake.decision == protocol::CommandGate::Decision::Refused ? intake.error.code : gate_.last_result();
  const ResultCode r = command(intake.command);
  gate_.record(r);
  return r;
}

void LinuxcncController::write_heartbeat(std::uint16_t counter) {
  if (counter == heartbeat_) return;
  heartbeat_ = counter;
  heartbeat_changed_ = std::chrono::steady_clock::now();  // after the calls to LinuxCNC, which may block
}

protocol::Status LinuxcncController::status() const {
  protocol::Status s;
  s.state = state_;
  s.alarm = alarm_;
  s.alarm_line = alarm_line_;
  s.heartbeat_echo = heartbeat_;
  s.boot_count = boot_count_;
  s.heartbeat_timeout_ms = std::uint16_t(std::clamp(options_.heartbeat_timeout_s * 1000.0, 0.0, 65535.0));
  acceptor_.fill_status(s);
  gate_.fill_status(s);
  s.last_executed_chunk = last_executed_chunk_;
  s.last_executed_line = last_executed_line_;
  if (last_.connected) {
    s.active_tool = std::uint16_t(std::clamp(last_.tool, 0, 65535));
    s.x_um = micrometres(last_.position[0]);
    s.y_um = micrometres(last_.position[1]);
    s.z_um = micrometres(last_.position[2]);
    const double rpm = last_.spindle_direction == 0 ? 0.0 : std::abs(last_.spindle_speed);
    s.spindle_rpm = std::int32_t(std::lround(last_.spindle_direction < 0 ? -rpm : rpm));
    s.feed_override_percent = std::uint16_t(std::clamp(std::lround(last_.feedrate * 100.0), 0L, 65535L));
    s.deposition_on = last_.dout[0];
  }
  return s;
}

void LinuxcncController::raise(AlarmCode code, std::uint32_t line, const std::string& what) {
  state_ = ControllerState::Alarm;
  alarm_ = code;
  alarm_line_ = line;
  const std::string entry =
      (line ? "line " + std::to_string(line) + ": " : std::string()) + std::string(protocol::to_string(code)) + ": " + what;
  report_.alarms.push_back(entry);
  if (options_.log) options_.log("alarm " + entry);
}

// docs/protocol.md, "Controller states and commands"; what each does to LinuxCNC is in
// docs/bridge.md.
ResultCode LinuxcncController::command(const protocol::Command& c) {
  switch (c.code) {
    case CommandCode::SetProgram: return set_program(c);
    case CommandCode::Start: return start();
    case CommandCode::FeedHold:
      if (state_ != ControllerState::Running && state_ != ControllerState::FeedHold) return ResultCode::WrongState;
      if (state_ == ControllerState::Running && segment_) {
        try {
          link_.pause();
        } catch (const LinkError& e) {
          raise(AlarmCode::LinuxcncError, last_executed_line_ + 1, std::string("feed hold: ") + e.what());
          return ResultCode::Accepted;
        }
      }
      hold_requested_ = true;
      state_ = ControllerState::FeedHold;
      return ResultCode::Accepted;
    case CommandCode::Resume:
      if (state_ != ControllerState::FeedHold) return ResultCode::WrongState;
      return resume();
    case CommandCode::Abort: return abort();
    case CommandCode::ResetAlarm: return reset_alarm();
    case CommandCode::OperatorAck:
      if (state_ != ControllerState::ProgramStop && state_ != ControllerState::OptionalStop) return ResultCode::WrongState;
      return resume();
    case CommandCode::None: break;
  }
  return ResultCode::UnknownCommand;
}

ResultCode LinuxcncController::set_program(const protocol::Command& c) {
  if (state_ != ControllerState::Idle && state_ != ControllerState::Completed && state_ != ControllerState::Aborted)
    return ResultCode::WrongState;
  if (c.identity == 0 || c.line_count == 0) return ResultCode::BadArgument;
  acceptor_.set_program(c.identity, c.line_count);
  feeder_.clear();
  segment_.reset();
  chunk_ends_.clear();
  last_executed_chunk_ = last_executed_line_ = 0;
  started_ = aborted_ = hold_requested_ = false;
  alarm_ = AlarmCode::None;
  alarm_line_ = 0;
  state_ = ControllerState::Idle;
  return ResultCode::Accepted;
}

ResultCode LinuxcncController::start() {
  if (!acceptor_.has_program()) return ResultCode::NoProgram;
  if (state_ != ControllerState::Idle) return ResultCode::WrongState;
  if (!last_.connected) {
    raise(AlarmCode::LinuxcncLost, 0, "LinuxCNC does not answer: " + last_.why);
    return ResultCode::Accepted;
  }
  try {
    link_.prepare(options_.feed_override);
    prepared_ = true;
  } catch (const LinkError& e) {
    raise(AlarmCode::LinuxcncError, 1, std::string("LinuxCNC could not be readied: ") + e.what());
    return ResultCode::Accepted;
  }
  state_ = ControllerState::Running;
  started_ = true;
  heartbeat_changed_ = std::chrono::steady_clock::now();  // after the calls to LinuxCNC, which may block
  return ResultCode::Accepted;
}

// RESUME after a feed hold, OPERATOR_ACK after M0/M1: LinuxCNC's paused program goes on;
// without one (held between segments, or after an alarm) the next segment starts.
ResultCode LinuxcncController::resume() {
  try {
    if (segment_ && last_.paused) {
      link_.resume();
    } else if (!segment_ && !prepared_) {
      link_.prepare(options_.feed_override);
      prepared_ = true;
    }
  } catch (const LinkError& e) {
    raise(AlarmCode::LinuxcncError, last_executed_line_ + 1, std::string("resume: ") + e.what());
    return ResultCode::Accepted;
  }
  hold_requested_ = false;
  state_ = ControllerState::Running;
  heartbeat_changed_ = std::chrono::steady_clock::now();  // after the calls to LinuxCNC, which may block
  return ResultCode::Accepted;
}

ResultCode LinuxcncController::abort() {
  if (!acceptor_.has_program() || state_ == ControllerState::Completed || state_ == ControllerState::Aborted)
    return ResultCode::Accepted;
  if (segment_ && last_.connected) {
    try {
      link_.abort();
    } catch (const LinkError& e) {
      if (options_.log) options_.log(std::string("abort: ") + e.what());
    }
  }
  segment_.reset();
  feeder_.clear();
  acceptor_.discard_queue();
  aborted_ = true;
  if (state_ != ControllerState::Alarm) state_ = ControllerState::Aborted;
  return ResultCode::Accepted;
}

ResultCode LinuxcncController::reset_alarm() {
  if (state_ != ControllerState::Alarm) return ResultCode::WrongState;
  if (alarm_ == AlarmCode::EmergencyStop && last_.connected && last_.estop) return ResultCode::ConditionActive;
  if (alarm_ == AlarmCode::LinuxcncLost && !last_.connected) return ResultCode::ConditionActive;
  alarm_ = AlarmCode::None;
  alarm_line_ = 0;
  state_ = aborted_ ? ControllerState::Aborted : started_ && !finished() ? ControllerState::FeedHold : ControllerState::Idle;
  return ResultCode::Accepted;
}

}  // namespace hybridctl::bridge
