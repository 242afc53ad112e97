// Status and command blocks in register form.

#include "protocol/messages.hpp"

#include <string>
#include <tuple>

#include "protocol/wire.hpp"

namespace hybridctl::protocol {

StatusRegisters encode_status(const Status& s) {
  namespace r = status_reg;
  StatusRegisters regs{};
  std::span<std::uint16_t> out(regs);
  out[r::kProtocolVersion] = s.protocol_version;
  out[r::kState] = static_cast<std::uint16_t>(s.state);
  out[r::kAlarm] = static_cast<std::uint16_t>(s.alarm);
  out[r::kChunkResult] = static_cast<std::uint16_t>(s.chunk_result);
  out[r::kCommandResult] = static_cast<std::uint16_t>(s.command_result);
  out[r::kCommandSeq] = s.command_seq;
  out[r::kCommandCode] = static_cast<std::uint16_t>(s.command_code);
  out[r::kHeartbeatEcho] = s.heartbeat_echo;
  out[r::kBootCount] = s.boot_count;
  out[r::kHeartbeatTimeoutMs] = s.heartbeat_timeout_ms;
  set_u32(out, r::kAlarmLine, s.alarm_line);
  set_u32(out, r::kLastWrittenChunk, s.last_written_chunk);
  set_u32(out, r::kLastAcceptedChunk, s.last_accepted_chunk);
  set_u32(out, r::kLastExecutedChunk, s.last_executed_chunk);
  set_u32(out, r::kLastExecutedLine, s.last_executed_line);
  set_u32(out, r::kNextLine, s.next_line);
  set_u32(out, r::kProgramLineCount, s.program_line_count);
  set_u64(out, r::kIdentity, s.identity);
  set_u32(out, r::kFreeBufferBytes, s.free_buffer_bytes);
  out[r::kMaxChunkPayload] = s.max_chunk_payload;
  out[r::kActiveTool] = s.active_tool;
  set_u32(out, r::kX, static_cast<std::uint32_t>(s.x_um));
  set_u32(out, r::kY, static_cast<std::uint32_t>(s.y_um));
  set_u32(out, r::kZ, static_cast<std::uint32_t>(s.z_um));
  set_u32(out, r::kSpindleRpm, static_cast<std::uint32_t>(s.spindle_rpm));
  out[r::kFeedOverride] = s.feed_override_percent;
  out[r::kFlags] = s.deposition_on ? r::kFlagDepositionOn : 0;
  set_u32(out, r::kDuplicateChunks, s.duplicate_chunks);
  set_u32(out, r::kRefusedChunks, s.refused_chunks);
  return regs;
}

namespace {

std::string reg_name(std::size_t offset, const char* field) {
  return "status register " + std::to_string(offset) + " (" + field + ")";
}

}  // namespace

Expected<Status> decode_status(std::span<const std::uint16_t> regs) {
  namespace r = status_reg;
  if (!regs.empty() && regs[r::kProtocolVersion] != kProtocolVersion)
    return ProtocolError{ResultCode::BadValue, "status protocol version " + std::to_string(regs[0]) +
                                                   ", this host speaks version " +
                                                   std::to_string(kProtocolVersion)};
  if (regs.size() != kStatusRegisters)
    return ProtocolError{ResultCode::BadLength, "status block of " + std::to_string(regs.size()) +
                                                    " registers, expected " + std::to_string(kStatusRegisters)};
  Status s;
  s.protocol_version = regs[r::kProtocolVersion];
  const auto state = controller_state_from_wire(regs[r::kState]);
  if (!state)
    return ProtocolError{ResultCode::BadValue, reg_name(r::kState, "state") + " is " +
                                                   std::to_string(regs[r::kState]) + ", expected 0.." +
                                                   std::to_string(kControllerStateCount - 1)};
  s.state = *state;
  const auto alarm = alarm_code_from_wire(regs[r::kAlarm]);
  if (!alarm)
    return ProtocolError{ResultCode::BadValue, reg_name(r::kAlarm, "alarm") + " is " +
                                                   std::to_string(regs[r::kAlarm]) + ", expected 0.." +
                                                   std::to_string(kAlarmCodeCount - 1)};
  s.alarm = *alarm;
  for (const auto& [offset, field, target] :
       {std::tuple{r::kChunkResult, "chunk result", &s.chunk_result},
        std::tuple{r::kCommandResult, "command result", &s.command_result}}) {
    const auto result = result_code_from_wire(regs[offset]);
    if (!result)
      return ProtocolError{ResultCode::BadValue, reg_name(offset, field) + " is " + std::to_string(regs[offset]) +
                                                     ", expected 0.." + std::to_string(kResultCodeCount - 1)};
    *target = *result;
  }
  s.command_seq = regs[r::kCommandSeq];
  const auto code = command_code_from_wire(regs[r::kCommandCode]);
  if (!code)
    return ProtocolError{ResultCode::BadValue, reg_name(r::kCommandCode, "command code") + " is " +
                                                   std::to_string(regs[r::kCommandCode]) + ", expected 0.." +
                                                   std::to_string(kCommandCodeCount - 1)};
  s.command_code = *code;
  s.heartbeat_echo = regs[r::kHeartbeatEcho];
  s.boot_count = regs[r::kBootCount];
  s.heartbeat_timeout_ms = regs[r::kHeartbeatTimeoutMs];
  s.alarm_line = reg_u32(regs, r::kAlarmLine);
  s.last_written_chunk = reg_u32(regs, r::kLastWrittenChunk);
  s.last_accepted_chunk = reg_u32(regs, r::kLastAcceptedChunk);
  s.last_executed_chunk = reg_u32(regs, r::kLastExecutedChunk);
  s.last_executed_line = reg_u32(regs, r::kLastExecutedLine);
  s.next_line = reg_u32(regs, r::kNextLine);
  s.program_line_count = reg_u32(regs, r::kProgramLineCount);
  s.identity = reg_u64(regs, r::kIdentity);
  s.free_buffer_bytes = reg_u32(regs, r::kFreeBufferBytes);
  s.max_chunk_payload = regs[r::kMaxChunkPayload];
  s.active_tool = regs[r::kActiveTool];
  s.x_um = static_cast<std::int32_t>(reg_u32(regs, r::kX));
  s.y_um = static_cast<std::int32_t>(reg_u32(regs, r::kY));
  s.z_um = static_cast<std::int32_t>(reg_u32(regs, r::kZ));
  s.spindle_rpm = static_cast<std::int32_t>(reg_u32(regs, r::kSpindleRpm));
  s.feed_override_percent = regs[r::kFeedOverride];
  s.deposition_on = (regs[r::kFlags] & r::kFlagDepositionOn) != 0;
  s.duplicate_chunks = reg_u32(regs, r::kDuplicateChunks);
  s.refused_chunks = reg_u32(regs, r::kRefusedChunks);
  return s;
}

std::vector<std::uint8_t> encode_status_bytes(const Status& status) {
  const auto regs = encode_status(status);
  return registers_to_bytes(regs);
}

Expected<Status> decode_status_bytes(std::span<const std::uint8_t> bytes) {
  if (bytes.size() != kStatusBytes) {
    // Still report a foreign protocol version first, as decode_status does.
    if (bytes.size() >= 2 && get_u16(bytes, 0) != kProtocolVersion)
      return ProtocolError{ResultCode::BadValue, "status protocol version " + std::to_string(get_u16(bytes, 0)) +
                                                     ", this host speaks version " +
                                                     std::to_string(kProtocolVersion)};
    return ProtocolError{ResultCode::BadLength, "status block of " + std::to_string(bytes.size()) +
                                                    " bytes, expected " + std::to_string(kStatusBytes)};
  }
  const auto regs = bytes_to_registers(bytes);
  return decode_status(regs);
}

CommandRegisters encode_command(const Command& c) {
  CommandRegisters regs{};
  std::span<std::uint16_t> out(regs);
  out[command_reg::kCode] = static_cast<std::uint16_t>(c.code);
  out[command_reg::kSeq] = c.seq;
  set_u64(out, command_reg::kIdentity, c.identity);
  set_u32(out, command_reg::kLineCount, c.line_count);
  return regs;
}

Expected<Command> decode_command(std::span<const std::uint16_t> regs) {
  if (regs.size() != kCommandRegisters)
    return ProtocolError{ResultCode::BadLength, "command block of " + std::to_string(regs.size()) +
                                                    " registers, expected " + std::to_string(kCommandRegisters)};
  Command c;
  c.seq = regs[command_reg::kSeq];
  if (c.seq == 0)
    return ProtocolError{ResultCode::BadValue, "command register 1 (seq) is 0, which means no command; "
                                               "expected 1..65535"};
  const auto code = command_code_from_wire(regs[command_reg::kCode]);
  if (!code || *code == CommandCode::None)
    return ProtocolError{ResultCode::UnknownCommand, "command register 0 (code) is " +
                                                         std::to_string(regs[command_reg::kCode]) +
                                                         ", expected 1.." + std::to_string(kCommandCodeCount - 1)};
  c.code = *code;
  if (c.code == CommandCode::SetProgram) {
    c.identity = reg_u64(regs, command_reg::kIdentity);
    c.line_count = reg_u32(regs, command_reg::kLineCount);
    if (c.line_count == 0)
      return ProtocolError{ResultCode::BadArgument, "SET_PROGRAM with a line count of 0 (command registers 6-7)"};
    if (c.identity == 0)
      return ProtocolError{ResultCode::BadArgument,
                           "SET_PROGRAM with identity 0 (command registers 2-5), which means no program"};
  }
  return c;
}

std::vector<std::uint8_t> registers_to_bytes(std::span<const std::uint16_t> registers) {
  std::vector<std::uint8_t> out;
  out.reserve(2 * registers.size());
  for (std::uint16_t r : registers) put_u16(out, r);
  return out;
}

std::vector<std::uint16_t> bytes_to_registers(std::span<const std::uint8_t> bytes) {
  std::vector<std::uint16_t> out(bytes.size() / 2);
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = get_u16(bytes, 2 * i);
  return out;
}

}  // namespace hybridctl::protocol
