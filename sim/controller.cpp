#include "sim/controller.hpp"

#include <algorithm>
#include <cmath>

#include "protocol/modbus_map.hpp"
#include "sim/executor.hpp"

namespace hybridctl::sim {

using protocol::AlarmCode;
using protocol::CommandCode;
using protocol::ControllerState;
using protocol::ResultCode;

struct Controller::Impl {
  const config::Machine& machine;
  ControllerOptions options;
  protocol::ChunkAcceptor acceptor;
  protocol::CommandGate gate;
  ControllerState state = ControllerState::Idle;
  AlarmCode alarm = AlarmCode::None;
  std::uint32_t alarm_line = 0;
  std::uint16_t boot_count = 1;
  std::uint16_t heartbeat = 0;
  double now = 0;                 // real seconds since start (sum of advance())
  double heartbeat_changed = 0;   // `now` of the last heartbeat change
  double virtual_time = 0;        // machine seconds executed
  double virtual_allowed = 0;     // what the clock allows so far (time scale > 0)
  bool alarm_at_line_fired = false;
  bool hold_at_line_fired = false;

  // The program being executed: the chunk in hand and the next line in it.
  std::optional<protocol::Chunk> chunk;
  std::vector<std::string_view> chunk_lines;
  std::size_t next_in_chunk = 0;
  std::uint32_t last_executed_chunk = 0, last_executed_line = 0;
  bool started = false;  // START received for the current program

  std::unique_ptr<ProgramExecutor> executor;
  std::vector<std::uint32_t> executed;
  std::vector<std::string> alarms;
  std::uint32_t chunks_accepted = 0, chunks_executed = 0, reboots = 0;

  Impl(const config::Machine& m, ControllerOptions o)
      : machine(m),
        options(std::move(o)),
        acceptor({options.buffer_bytes, options.max_chunk_payload}) {
    ExecutorOptions eo;
    eo.stock = options.stock;
    eo.protected_region = options.protected_region;
    executor = std::make_unique<ProgramExecutor>(machine, "program", std::move(eo));
  }

  void raise(AlarmCode code, std::uint32_t line, const std::string& what) {
    state = ControllerState::Alarm;
    alarm = code;
    alarm_line = line;
    alarms.push_back((line ? "line " + std::to_string(line) + ": " : std::string()) + std::string(protocol::to_string(code)) +
                     ": " + what);
  }

  // A warning (protocol::AlarmInfo::warning): reported in the status and the run report,
  // the state stays as it is; it latches until the next alarm or SET_PROGRAM.
  void warn(AlarmCode code, std::uint32_t line, const std::string& what) {
    alarm = code;
    alarm_line = line;
    alarms.push_back("line " + std::to_string(line) + ": " + std::string(protocol::to_string(code)) + " (warning): " + what);
  }

  bool aborted = false;  // ABORT arrived (in ALARM it takes effect at RESET_ALARM)
  bool finished() const { return acceptor.has_program() && last_executed_line >= acceptor.line_count(); }

  // docs/protocol.md, "Controller states and commands".
  ResultCode command(const protocol::Command& c) {
    switch (c.code) {
      case CommandCode::SetProgram:
        if (state != ControllerState::Idle && state != ControllerState::Completed && state != ControllerState::Aborted)
          return ResultCode::WrongState;
        if (c.identity == 0 || c.line_count == 0) return ResultCode::BadArgument;
        acceptor.set_program(c.identity, c.line_count);
        // A new program starts from the machine's power-on modal state (an earlier M2
        // ended the last one); the material and the position stay where they are.
        {
          ExecutorOptions eo;
          if (options.stock) eo.stock = executor->stock();
          eo.protected_region = options.protected_region;
          gcode::InterpreterOptions io;
          io.start = executor->state().position;
          executor = std::make_unique<ProgramExecutor>(machine, "program", std::move(eo), io);
        }
        chunk.reset();
        chunk_lines.clear();
        next_in_chunk = 0;
        last_executed_chunk = last_executed_line = 0;
        executed.clear();
        started = aborted = false;
        alarm = AlarmCode::None;
        alarm_line = 0;
        state = ControllerState::Idle;
        return ResultCode::Accepted;
      case CommandCode::Start:
        if (!acceptor.has_program()) return ResultCode::NoProgram;
        if (state != ControllerState::Idle) return ResultCode::WrongState;
        state = ControllerState::Running;
        started = true;
        heartbeat_changed = now;
        return ResultCode::Accepted;
      case CommandCode::FeedHold:
        if (state != ControllerState::Running && state != ControllerState::FeedHold) return ResultCode::WrongState;
        state = ControllerState::FeedHold;
        return ResultCode::Accepted;
      case CommandCode::Resume:
        if (state != ControllerState::FeedHold) return ResultCode::WrongState;
        state = ControllerState::Running;
        heartbeat_changed = now;
        return ResultCode::Accepted;
      case CommandCode::Abort:
        if (acceptor.has_program() && state != ControllerState::Completed && state != ControllerState::Aborted) {
          acceptor.discard_queue();
          chunk.reset();
          chunk_lines.clear();
          aborted = true;
          if (state != ControllerState::Alarm) state = ControllerState::Aborted;
        }
        return ResultCode::Accepted;
      case CommandCode::ResetAlarm:
        if (state != ControllerState::Alarm) return ResultCode::WrongState;
        alarm = AlarmCode::None;
        alarm_line = 0;
        state = aborted                  ? ControllerState::Aborted
                : started && !finished() ? ControllerState::FeedHold
                                         : ControllerState::Idle;
        return ResultCode::Accepted;
      case CommandCode::OperatorAck:
        if (state != ControllerState::ProgramStop && state != ControllerState::OptionalStop) return ResultCode::WrongState;
        state = ControllerState::Running;
        heartbeat_changed = now;
        return ResultCode::Accepted;
      case CommandCode::None: break;
    }
    return ResultCode::UnknownCommand;
  }

  // A chunk of another program while running: two hosts or two programs are mixed.
  void check_identity(const protocol::ChunkVerdict& v) {
    if (v.result == ResultCode::IdentityMismatch && state == ControllerState::Running)
      raise(AlarmCode::ProgramIdentityMismatch, 0, v.message);
  }

  // The next line to execute, taking the next chunk when the one in hand is done.
  bool next_line(std::string_view& text, std::uint32_t& number) {
    while (!chunk || next_in_chunk >= chunk_lines.size()) {
      if (chunk) {
        last_executed_chunk = chunk->seq;
        ++chunks_executed;
        chunk.reset();
      }
      auto taken = acceptor.take();
      if (!taken) return false;
      chunk = std::move(*taken);
      chunk_lines.clear();
      next_in_chunk = 0;
      std::string_view payload(chunk->payload);
      std::size_t start = 0;
      while (start < payload.size()) {
        const std::size_t end = payload.find('\n', start);
        chunk_lines.push_back(payload.substr(start, (end == std::string_view::npos ? payload.size() : end) - start));
        start = end == std::string_view::npos ? payload.size() : end + 1;
      }
    }
    text = chunk_lines[next_in_chunk];
    number = chunk->first_line + std::uint32_t(next_in_chunk);
    return true;
  }

  // Executes one line; false when nothing could run (nothing queued, or it stopped).
  bool step() {
    std::string_view text;
    std::uint32_t number = 0;
    if (!next_line(text, number)) {
      if (finished()) {
        state = ControllerState::Completed;
      } else if (options.time_scale > 0 && executor->state().any_deposition()) {
        // A bead must not stop growing in place for lack of lines. (As fast as possible,
        // time scale 0, the controller outruns any host: no starvation is simulated.)
        raise(AlarmCode::DepositionStarved, last_executed_line, "the buffer ran empty while depositing");
      }
      return false;
    }
    if (options.alarm_at_line && number == options.alarm_at_line && !alarm_at_line_fired) {
      alarm_at_line_fired = true;
      raise(AlarmCode::EmergencyStop, number, "emergency stop (injected before this line)");
      return false;
    }
    if (options.hold_at_line && number == options.hold_at_line && !hold_at_line_fired) {
      hold_at_line_fired = true;
      state = ControllerState::FeedHold;
      return false;
    }
    const LineOutcome o = executor->execute_line(text, int(number));
    virtual_time += o.seconds;
    switch (o.stop) {
      case Stop::None: break;
      case Stop::GcodeError: raise(AlarmCode::GcodeError, number, o.message); return false;
      case Stop::EnvelopeViolation: raise(AlarmCode::EnvelopeViolation, number, o.message); return false;
      case Stop::ToolNotInMagazine: raise(AlarmCode::ToolNotInMagazine, number, o.message); return false;
      case Stop::DepositionWithoutHead: raise(AlarmCode::DepositionWithoutHead, number, o.message); return false;
      case Stop::SpindleDepositionConflict: raise(AlarmCode::SpindleDepositionConflict, number, o.message); return false;
      case Stop::RapidIntoMaterial:
      case Stop::NozzleCollision:
        // The crash has happened: the line counts as executed, the machine stops.
        break;
    }
    // A bead over air fell: a warning, the program goes on (docs/simulator.md).
    for (const Incident& inc : o.incidents)
      if (inc.kind == IncidentKind::UnsupportedDeposition) warn(AlarmCode::DepositionOverAir, number, describe(inc));
    ++next_in_chunk;
    last_executed_line = number;
    executed.push_back(number);
    if (options.on_line_executed) options.on_line_executed(number, text);
    if (next_in_chunk >= chunk_lines.size()) {
      last_executed_chunk = chunk->seq;
      ++chunks_executed;
      chunk.reset();
    }
    if (o.stop == Stop::RapidIntoMaterial || o.stop == Stop::NozzleCollision) {
      raise(o.stop == Stop::RapidIntoMaterial ? AlarmCode::RapidIntoMaterial : AlarmCode::NozzleCollision, number,
            o.message);
      return false;
    }
    for (const gcode::Event& e : o.events) {
      if (e.kind == gcode::EventKind::ProgramStop) state = ControllerState::ProgramStop;
      if (e.kind == gcode::EventKind::OptionalStop) state = ControllerState::OptionalStop;
      if (e.kind == gcode::EventKind::ProgramEnd) state = ControllerState::Completed;
    }
    if (state == ControllerState::Running && last_executed_line >= acceptor.line_count())
      state = ControllerState::Completed;
    if (std::binary_search(options.break_after_lines.begin(), options.break_after_lines.end(), number)) return false;
    return state == ControllerState::Running;
  }

  void advance(double real_seconds) {
    now += std::max(0.0, real_seconds);
    if (state == ControllerState::Running && options.heartbeat_timeout_s > 0 &&
        now - heartbeat_changed > options.heartbeat_timeout_s) {
      raise(AlarmCode::HostHeartbeatLost, 0,
            "no heartbeat change for " + std::to_string(options.heartbeat_timeout_s) + " s: motion held");
      return;
    }
    if (state != ControllerState::Running) {
      virtual_allowed = virtual_time;  // the clock does not bank time while stopped
      return;
    }
    if (options.time_scale <= 0) {
      for (std::uint32_t n = 0; n < options.max_lines_per_advance && step(); ++n) {
      }
      return;
    }
    virtual_allowed += real_seconds * options.time_scale;
    while (virtual_time < virtual_allowed && step()) {
    }
    if (virtual_allowed > virtual_time + 1.0) virtual_allowed = virtual_time + 1.0;  // starved: no burst later
  }
};

Controller::Controller(const config::Machine& machine, ControllerOptions options)
    : impl_(std::make_unique<Impl>(machine, std::move(options))) {}
Controller::~Controller() = default;

protocol::ChunkVerdict Controller::write_mailbox(std::span<const std::uint16_t> registers) {
  auto v = impl_->acceptor.offer_mailbox(registers, impl_->state);
  if (v.result == ResultCode::Accepted) ++impl_->chunks_accepted;
  impl_->check_identity(v);
  return v;
}

protocol::ChunkVerdict Controller::write_message(std::span<const std::uint8_t> message) {
  auto v = impl_->acceptor.offer_message(message, impl_->state);
  if (v.result == ResultCode::Accepted) ++impl_->chunks_accepted;
  impl_->check_identity(v);
  return v;
}

protocol::ResultCode Controller::write_command(std::span<const std::uint16_t> registers) {
  const auto intake = impl_->gate.offer(registers);
  if (intake.decision == protocol::CommandGate::Decision::Execute) {
    const ResultCode r = impl_->command(intake.command);
    impl_->gate.record(r);
    return r;
  }
  return intake.decision == protocol::CommandGate::Decision::Refused ? intake.error.code : impl_->gate.last_result();
}

protocol::ResultCode Controller::write_command(const protocol::Command& command) {
  const auto intake = impl_->gate.offer(command);
  if (intake.decision == protocol::CommandGate::Decision::Execute) {
    const ResultCode r = impl_->command(intake.command);
    impl_->gate.record(r);
    return r;
  }
  return intake.decision == protocol::CommandGate::Decision::Refused ? intake.error.code : impl_->gate.last_result();
}

void Controller::write_heartbeat(std::uint16_t counter) {
  if (counter != impl_->heartbeat) {
    impl_->heartbeat = counter;
    impl_->heartbeat_changed = impl_->now;
  }
}

protocol::Status Controller::status() const {
  const Impl& i = *impl_;
  protocol::Status s;
  s.state = i.state;
  s.alarm = i.alarm;
  s.alarm_line = i.alarm_line;
  s.heartbeat_echo = i.heartbeat;
  s.boot_count = i.boot_count;
  s.heartbeat_timeout_ms = std::uint16_t(std::clamp(i.options.heartbeat_timeout_s * 1000.0, 0.0, 65535.0));
  i.acceptor.fill_status(s);
  i.gate.fill_status(s);
  s.last_executed_chunk = i.last_executed_chunk;
  s.last_executed_line = i.last_executed_line;
  const gcode::ModalState& m = i.executor->state();
  s.active_tool = std::uint16_t(std::clamp(m.tool, 0, 65535));
  auto um = [](double mm) { return std::int32_t(std::clamp(std::llround(mm * 1000.0), -2147483647LL, 2147483647LL)); };
  s.x_um = um(m.position.x);
  s.y_um = um(m.position.y);
  s.z_um = um(m.position.z);
  const double rpm = m.spindle == gcode::SpindleState::Off ? 0 : m.spindle_speed;
  s.spindle_rpm = std::int32_t(m.spindle == gcode::SpindleState::Ccw ? -rpm : rpm);
  s.deposition_on = m.any_deposition();
  return s;
}

protocol::ControllerState Controller::state() const { return impl_->state; }
protocol::AlarmCode Controller::alarm() const { return impl_->alarm; }

void Controller::advance(double real_seconds) { impl_->advance(real_seconds); }

void Controller::reboot() {
  Impl& i = *impl_;
  // What survives: the program's identity and how far it ran (non-volatile), the machine's
  // position, tool and modal state (the executor: the controller restores them for a
  // mid-program restart), and the material. Lost: the queue and the chunk in hand.
  protocol::SafePoint safe{i.acceptor.identity(), i.acceptor.line_count(), i.last_executed_chunk, i.last_executed_line};
  protocol::ChunkAcceptor fresh({i.options.buffer_bytes, i.options.max_chunk_payload});
  if (i.acceptor.has_program()) fresh.restore(safe);
  i.acceptor = std::move(fresh);
  i.chunk.reset();
  i.chunk_lines.clear();
  i.next_in_chunk = 0;
  i.gate = protocol::CommandGate();
  ++i.boot_count;
  ++i.reboots;
  i.heartbeat = 0;
  // docs/protocol.md, "Controller reboot": idle without a started program, completed or
  // aborted as it was, otherwise an alarm until the operator has looked.
  if (!i.acceptor.has_program() || !i.started) {
    i.state = ControllerState::Idle;
  } else if (i.finished()) {
    i.state = ControllerState::Completed;
  } else if (i.aborted) {
    i.state = ControllerState::Aborted;
  } else {
    i.raise(AlarmCode::ControllerRestarted, 0, "controller restarted: the program buffer was lost");
  }
}

void Controller::emergency_stop() { impl_->raise(AlarmCode::EmergencyStop, impl_->last_executed_line, "emergency stop"); }

ControllerReport Controller::report() const {
  const Impl& i = *impl_;
  ControllerReport r;
  r.identity = i.acceptor.identity();
  r.program_lines = i.acceptor.line_count();
  r.chunks_accepted = i.chunks_accepted;
  r.chunks_executed = i.chunks_executed;
  r.lines_executed = std::uint32_t(i.executed.size());
  r.duplicates = i.acceptor.duplicates();
  r.refused = i.acceptor.refused();
  r.reboots = i.reboots;
  r.virtual_time_s = i.virtual_time;
  r.alarms = i.alarms;
  const SimulationReport s = i.executor->report();
  r.removed_mm3 = s.removed;
  r.deposited_mm3 = s.deposited;
  r.gouge_mm3 = s.gouge;
  if (i.options.stock) r.as_built_mm3 = i.executor->stock().volume();
  r.completed = i.state == ControllerState::Completed;
  return r;
}

const std::vector<std::uint32_t>& Controller::executed_lines() const { return impl_->executed; }

geometry::Solid Controller::as_built() const { return impl_->executor->stock(); }

}  // namespace hybridctl::sim
