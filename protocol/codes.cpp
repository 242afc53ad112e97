// The alarm and result-code tables: the one place their names, numbers and meanings live.

#include "protocol/codes.hpp"

#include <array>

namespace hybridctl::protocol {
namespace {

constexpr std::array<AlarmInfo, kAlarmCodeCount> kAlarms{{
    {AlarmCode::None, "NONE", "No alarm.", "Nothing.", false},
    {AlarmCode::EnvelopeViolation, "ENVELOPE_VIOLATION",
     "A move at the alarm line would leave the machine's travel (arc bulges included); the "
     "controller stopped before it.",
     "Check the program's setup and work offsets against the machine file; ABORT and "
     "re-export, or fix the setup, RESET_ALARM and RESUME.",
     true},
    {AlarmCode::RapidIntoMaterial, "RAPID_INTO_MATERIAL",
     "A rapid (G0) move at the alarm line would pass through stock or deposited material.",
     "ABORT; check the stock and setup against the plan and re-export the program.", true},
    {AlarmCode::ToolNotInMagazine, "TOOL_NOT_IN_MAGAZINE",
     "The tool change at the alarm line asks for a tool number the magazine does not hold.",
     "Load the tool (or fix the tool table), RESET_ALARM and RESUME; or ABORT.", true},
    {AlarmCode::DepositionWithoutHead, "DEPOSITION_WITHOUT_HEAD",
     "Deposition was switched on at the alarm line while the active tool is not a deposition "
     "head.",
     "ABORT; the program misses a head change before depositing: re-export it.", true},
    {AlarmCode::HostHeartbeatLost, "HOST_HEARTBEAT_LOST",
     "While running, the host's heartbeat did not change for the heartbeat timeout (status "
     "`heartbeat_timeout_ms`); motion was held and deposition switched off.",
     "Restore the host connection; then RESET_ALARM (the state becomes FEED_HOLD) and "
     "RESUME. The queued chunks were kept.",
     false},
    {AlarmCode::GcodeError, "GCODE_ERROR",
     "The controller's interpreter rejected the G-code at the alarm line.",
     "ABORT; run `hybridctl gcode check` on the program and fix the line.", true},
    {AlarmCode::ProgramIdentityMismatch, "PROGRAM_IDENTITY_MISMATCH",
     "While a program was running, a chunk of another program arrived (its identity tag did "
     "not match): two hosts or two programs are mixed. Motion was held.",
     "Stop the other host; RESET_ALARM and RESUME this program, or ABORT it.", false},
    {AlarmCode::EmergencyStop, "EMERGENCY_STOP",
     "The emergency stop was pressed or the safety chain opened.",
     "Make the machine safe, release the emergency stop, RESET_ALARM; then RESUME or ABORT.",
     false},
    {AlarmCode::SpindleDepositionConflict, "SPINDLE_DEPOSITION_CONFLICT",
     "The line at the alarm line would run the spindle and the deposition head at the same time.",
     "ABORT; the program must stop the spindle before depositing and stop depositing before "
     "starting the spindle: re-export it.",
     true},
    {AlarmCode::ControllerRestarted, "CONTROLLER_RESTARTED",
     "The controller rebooted while a program was started and not finished; its chunk buffer "
     "was lost. The program's safe point (last executed chunk and line) survived.",
     "Check the machine (position, tool, part); RESET_ALARM (the state becomes FEED_HOLD), "
     "resend from the status' next chunk and next line, and RESUME; or ABORT.",
     false},
    {AlarmCode::DepositionStarved, "DEPOSITION_STARVED",
     "The chunk buffer ran empty while depositing; motion and deposition stopped mid-bead "
     "after the alarm line.",
     "Inspect the bead at the stop; RESET_ALARM and RESUME, or ABORT. Send chunks earlier "
     "(keep the buffer fuller) on this transport.",
     true},
    {AlarmCode::DepositionOverAir, "DEPOSITION_OVER_AIR",
     "A warning: the bead laid at the alarm line ran over air beyond the head's overhang cone and "
     "bridge (machine file `support`); that material fell and is missing. The program goes on; "
     "the warning stays in the status until the next alarm or SET_PROGRAM.",
     "Finish or ABORT the job; the part misses material from that line on. Re-plan with the "
     "head's support limits, or deposit a supported envelope and machine it back.",
     true, true},
    {AlarmCode::NozzleCollision, "NOZZLE_COLLISION",
     "The deposition head's nozzle body touched material on a feed move at the alarm line (the "
     "stand-off did not clear what is there); the controller stopped after it.",
     "ABORT; inspect the nozzle and the part. The program deposits under or beside material "
     "the nozzle cannot pass: re-plan or re-export it.",
     true},
    {AlarmCode::LinuxcncError, "LINUXCNC_ERROR",
     "LinuxCNC reported an error the other codes do not name (its error channel; the bridge "
     "logs LinuxCNC's message) and stopped the program at the alarm line.",
     "Read LinuxCNC's message in the bridge's log; fix the cause, RESET_ALARM and RESUME, or "
     "ABORT.",
     true},
    {AlarmCode::LinuxcncLost, "LINUXCNC_LOST",
     "The LinuxCNC bridge lost LinuxCNC (it stopped or restarted): the program in LinuxCNC, "
     "its position and modal state are gone. When LinuxCNC is back the bridge counts a new "
     "boot without the program.",
     "Check the machine (position, tool, part); the host reports a controller loss and "
     "the lines that ran; restart with `run --resume DIR --from-line N`.",
     false},
}};

constexpr std::array<ResultInfo, kResultCodeCount> kResults{{
    {ResultCode::None, "NONE", "No chunk (resp. command) was written since the controller booted.",
     "Nothing."},
    {ResultCode::Accepted, "ACCEPTED", "The chunk was queued; the command was executed.",
     "Send the next chunk."},
    {ResultCode::Duplicate, "DUPLICATE",
     "The chunk's sequence number is at most the last accepted one: acknowledged, not queued "
     "again (a retry of a write whose reply was lost).",
     "Continue from the status' last accepted chunk + 1."},
    {ResultCode::Gap, "GAP",
     "The chunk's sequence number is beyond the last accepted one + 1; refused.",
     "Resend from the status' last accepted chunk + 1, starting at its next line."},
    {ResultCode::BadCrc, "BAD_CRC", "The payload's CRC-32 does not match the header's; refused.",
     "Resend the same chunk."},
    {ResultCode::BadLength, "BAD_LENGTH",
     "The write or message is shorter or longer than its header says (or a padding byte is "
     "not zero); refused.",
     "Resend the same chunk; if it repeats, the host's encoder is wrong."},
    {ResultCode::TooLong, "TOO_LONG",
     "The payload is longer than the status' max chunk payload (or than the transport "
     "carries); refused.",
     "Resend the lines in smaller chunks."},
    {ResultCode::BadLines, "BAD_LINES",
     "The payload does not hold exactly `line count` lines each ending in a newline; refused.",
     "Fix the host's chunker; resend."},
    {ResultCode::BadText, "BAD_TEXT", "The payload holds a NUL or a byte above 0x7F; refused.",
     "Fix the program text (ASCII only); set the program again."},
    {ResultCode::LineMismatch, "LINE_MISMATCH",
     "The chunk's first line is not the status' next line, or its lines run past the "
     "program's line count; refused.",
     "Resend starting at the status' next line."},
    {ResultCode::BufferFull, "BUFFER_FULL",
     "The payload is longer than the status' free buffer space; refused.",
     "Resend the same chunk when the free space allows."},
    {ResultCode::NoProgram, "NO_PROGRAM",
     "No program is set (SET_PROGRAM): a chunk or START was refused.",
     "Send SET_PROGRAM, then the chunks from 1."},
    {ResultCode::IdentityMismatch, "IDENTITY_MISMATCH",
     "The chunk's identity tag is not the low 32 bits of the set program's identity; refused.",
     "Do not mix programs: stream the program the controller holds, or ABORT it and set yours."},
    {ResultCode::NotAccepting, "NOT_ACCEPTING",
     "The controller takes no chunks in its state (alarm, completed, aborted); refused.",
     "Clear the alarm (RESET_ALARM), or set a new program."},
    {ResultCode::UnknownCommand, "UNKNOWN_COMMAND", "The command code is not defined; ignored.",
     "Fix the host (protocol version mismatch?)."},
    {ResultCode::WrongState, "WRONG_STATE",
     "The command is not allowed in the controller's state; ignored.",
     "Read the state; see the command table in docs/protocol.md."},
    {ResultCode::BadArgument, "BAD_ARGUMENT",
     "A command argument is out of range (SET_PROGRAM with 0 lines or identity 0); ignored.",
     "Fix the host."},
    {ResultCode::ConditionActive, "CONDITION_ACTIVE",
     "RESET_ALARM while the alarm's cause is still present (emergency stop still pressed); the "
     "alarm stays.",
     "Remove the cause, then RESET_ALARM again."},
    {ResultCode::BadValue, "BAD_VALUE",
     "A field holds a value outside its range (sequence number 0, line 0, unknown state, "
     "protocol version); refused.",
     "Fix the encoder on the side that sent it."},
}};

// Markdown cells: '|' would end a cell.
std::string cell(std::string_view text) {
  std::string out;
  for (char c : text) {
    if (c == '|') out += "\\|";
    else out += c;
  }
  return out;
}

}  // namespace

const AlarmInfo& alarm_info(AlarmCode code) {
  const auto i = static_cast<std::size_t>(code);
  return i < kAlarms.size() ? kAlarms[i] : kAlarms[0];
}

const ResultInfo& result_info(ResultCode code) {
  const auto i = static_cast<std::size_t>(code);
  return i < kResults.size() ? kResults[i] : kResults[0];
}

std::string_view to_string(ControllerState state) {
  switch (state) {
    case ControllerState::Idle: return "IDLE";
    case ControllerState::Running: return "RUNNING";
    case ControllerState::FeedHold: return "FEED_HOLD";
    case ControllerState::ProgramStop: return "PROGRAM_STOP";
    case ControllerState::OptionalStop: return "OPTIONAL_STOP";
    case ControllerState::Alarm: return "ALARM";
    case ControllerState::Completed: return "COMPLETED";
    case ControllerState::Aborted: return "ABORTED";
  }
  return "UNKNOWN_STATE";
}

std::string_view to_string(CommandCode code) {
  switch (code) {
    case CommandCode::None: return "NONE";
    case CommandCode::SetProgram: return "SET_PROGRAM";
    case CommandCode::Start: return "START";
    case CommandCode::FeedHold: return "FEED_HOLD";
    case CommandCode::Resume: return "RESUME";
    case CommandCode::Abort: return "ABORT";
    case CommandCode::ResetAlarm: return "RESET_ALARM";
    case CommandCode::OperatorAck: return "OPERATOR_ACK";
  }
  return "UNKNOWN_COMMAND";
}

std::string_view to_string(AlarmCode code) {
  const auto i = static_cast<std::size_t>(code);
  return i < kAlarms.size() ? kAlarms[i].name : std::string_view("UNKNOWN_ALARM");
}

std::string_view to_string(ResultCode code) {
  const auto i = static_cast<std::size_t>(code);
  return i < kResults.size() ? kResults[i].name : std::string_view("UNKNOWN_RESULT");
}

std::optional<ControllerState> controller_state_from_wire(std::uint16_t value) {
  if (value >= kControllerStateCount) return std::nullopt;
  return static_cast<ControllerState>(value);
}
std::optional<CommandCode> command_code_from_wire(std::uint16_t value) {
  if (value >= kCommandCodeCount) return std::nullopt;
  return static_cast<CommandCode>(value);
}
std::optional<AlarmCode> alarm_code_from_wire(std::uint16_t value) {
  if (value >= kAlarmCodeCount) return std::nullopt;
  return static_cast<AlarmCode>(value);
}
std::optional<ResultCode> result_code_from_wire(std::uint16_t value) {
  if (value >= kResultCodeCount) return std::nullopt;
  return static_cast<ResultCode>(value);
}

std::string alarm_table_markdown() {
  std::string out = "| Code | Name | Line | Kind | Meaning | What the operator does |\n";
  out += "|---:|---|:---:|:---:|---|---|\n";
  for (const auto& a : kAlarms) {
    out += "| " + std::to_string(static_cast<unsigned>(a.code)) + " | `" + std::string(a.name) +
           "` | " + (a.has_line ? "yes" : "-") + " | " + (a.warning ? "warning" : "stop") + " | " + cell(a.meaning) +
           " | " + cell(a.action) + " |\n";
  }
  return out;
}

std::string result_table_markdown() {
  std::string out = "| Code | Name | Meaning | What the host does |\n";
  out += "|---:|---|---|---|\n";
  for (const auto& r : kResults) {
    out += "| " + std::to_string(static_cast<unsigned>(r.code)) + " | `" + std::string(r.name) +
           "` | " + cell(r.meaning) + " | " + cell(r.action) + " |\n";
  }
  return out;
}

}  // namespace hybridctl::protocol
