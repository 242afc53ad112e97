#pragma once
// The status block (controller -> host) and the command block (host -> controller), and
// their register form: the Modbus input registers (status), holding registers (command),
// and, as big-endian bytes, the CAN status frames. docs/protocol.md, "Status block" and
// "Commands", has the tables; the offsets below are the code's copy of them.

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "protocol/codes.hpp"

namespace hybridctl::protocol {

/// What the controller reports. Positions in micrometres in the machine frame.
struct Status {
  std::uint16_t protocol_version = kProtocolVersion;
  ControllerState state = ControllerState::Idle;
  AlarmCode alarm = AlarmCode::None;
  ResultCode chunk_result = ResultCode::None;    ///< result of the last chunk write
  ResultCode command_result = ResultCode::None;  ///< result of the last executed command seq
  std::uint16_t command_seq = 0;                 ///< seq of the last command processed (0: none)
  CommandCode command_code = CommandCode::None;  ///< code of that command
  std::uint16_t heartbeat_echo = 0;              ///< last host heartbeat value seen
  std::uint16_t boot_count = 0;                  ///< +1 at every controller (re)boot, wraps
  std::uint16_t heartbeat_timeout_ms = 2000;     ///< RUNNING + no heartbeat change this long -> alarm
  std::uint32_t alarm_line = 0;                  ///< program line the alarm refers to, 0: none
  std::uint32_t last_written_chunk = 0;          ///< seq of the last chunk write (any result; 0: none)
  std::uint32_t last_accepted_chunk = 0;         ///< highest seq queued; chunks 1..this are in
  std::uint32_t last_executed_chunk = 0;         ///< highest seq whose lines all executed
  std::uint32_t last_executed_line = 0;          ///< last program line whose execution completed
  std::uint32_t next_line = 0;                   ///< first line chunk last_accepted+1 must carry (0: no program)
  std::uint32_t program_line_count = 0;          ///< from SET_PROGRAM
  std::uint64_t identity = 0;                    ///< from SET_PROGRAM (0: none set)
  std::uint32_t free_buffer_bytes = 0;           ///< payload bytes the next chunk may occupy
  std::uint16_t max_chunk_payload = 0;           ///< largest payload accepted in one chunk
  std::uint16_t active_tool = 0;                 ///< tool or head number, 0: none
  std::int32_t x_um = 0;
  std::int32_t y_um = 0;
  std::int32_t z_um = 0;
  std::int32_t spindle_rpm = 0;                  ///< > 0 clockwise (M3), < 0 counter-clockwise (M4)
  std::uint16_t feed_override_percent = 100;
  bool deposition_on = false;
  std::uint32_t duplicate_chunks = 0;            ///< DUPLICATE results since boot
  std::uint32_t refused_chunks = 0;              ///< results other than ACCEPTED/DUPLICATE since boot

  friend bool operator==(const Status&, const Status&) = default;
};

/// Register offsets inside the status block (0-based). 32-bit values span two registers,
/// high word first; the identity spans four, most significant first.
namespace status_reg {
inline constexpr std::size_t kProtocolVersion = 0;
inline constexpr std::size_t kState = 1;
inline constexpr std::size_t kAlarm = 2;
inline constexpr std::size_t kChunkResult = 3;
inline constexpr std::size_t kCommandResult = 4;
inline constexpr std::size_t kCommandSeq = 5;
inline constexpr std::size_t kCommandCode = 6;
inline constexpr std::size_t kHeartbeatEcho = 7;
inline constexpr std::size_t kBootCount = 8;
inline constexpr std::size_t kHeartbeatTimeoutMs = 9;
inline constexpr std::size_t kAlarmLine = 10;
inline constexpr std::size_t kLastWrittenChunk = 12;
inline constexpr std::size_t kLastAcceptedChunk = 14;
inline constexpr std::size_t kLastExecutedChunk = 16;
inline constexpr std::size_t kLastExecutedLine = 18;
inline constexpr std::size_t kNextLine = 20;
inline constexpr std::size_t kProgramLineCount = 22;
inline constexpr std::size_t kIdentity = 24;
inline constexpr std::size_t kFreeBufferBytes = 28;
inline constexpr std::size_t kMaxChunkPayload = 30;
inline constexpr std::size_t kActiveTool = 31;
inline constexpr std::size_t kX = 32;
inline constexpr std::size_t kY = 34;
inline constexpr std::size_t kZ = 36;
inline constexpr std::size_t kSpindleRpm = 38;
inline constexpr std::size_t kFeedOverride = 40;
inline constexpr std::size_t kFlags = 41;
inline constexpr std::size_t kDuplicateChunks = 42;
inline constexpr std::size_t kRefusedChunks = 44;
inline constexpr std::size_t kCount = 46;
/// Bits of the flags register; the others are sent as 0 and ignored.
inline constexpr std::uint16_t kFlagDepositionOn = 0x0001;
}  // namespace status_reg

inline constexpr std::size_t kStatusRegisters = status_reg::kCount;
inline constexpr std::size_t kStatusBytes = 2 * kStatusRegisters;

using StatusRegisters = std::array<std::uint16_t, kStatusRegisters>;

StatusRegisters encode_status(const Status& status);

/// Decodes exactly kStatusRegisters registers. Errors: protocol version not ours (BAD_VALUE,
/// checked first), another count (BAD_LENGTH), a state, alarm, result or command code this
/// version does not define (BAD_VALUE naming the register).
Expected<Status> decode_status(std::span<const std::uint16_t> registers);

/// The status block as bytes (each register big-endian): the CAN status frames' content.
std::vector<std::uint8_t> encode_status_bytes(const Status& status);
Expected<Status> decode_status_bytes(std::span<const std::uint8_t> bytes);

/// A host command. identity and line_count are SET_PROGRAM's arguments; other commands
/// send them as 0 and the decoder returns them as 0.
struct Command {
  CommandCode code = CommandCode::None;
  std::uint16_t seq = 0;  ///< 1..65535, a new value for every new command (wraps 65535 -> 1)
  std::uint64_t identity = 0;
  std::uint32_t line_count = 0;

  friend bool operator==(const Command&, const Command&) = default;
};

/// Register offsets inside the command block.
namespace command_reg {
inline constexpr std::size_t kCode = 0;
inline constexpr std::size_t kSeq = 1;
inline constexpr std::size_t kIdentity = 2;   ///< 4 registers, most significant first
inline constexpr std::size_t kLineCount = 6;  ///< 2 registers, high word first
inline constexpr std::size_t kCount = 8;
}  // namespace command_reg

inline constexpr std::size_t kCommandRegisters = command_reg::kCount;
using CommandRegisters = std::array<std::uint16_t, kCommandRegisters>;

CommandRegisters encode_command(const Command& command);

/// Decodes exactly kCommandRegisters registers. Errors: another count (BAD_LENGTH); seq 0
/// (BAD_VALUE: 0 means "no command"); code 0 or unknown (UNKNOWN_COMMAND); SET_PROGRAM with
/// 0 lines or identity 0 (BAD_ARGUMENT; identity 0 means "no program").
Expected<Command> decode_command(std::span<const std::uint16_t> registers);

/// The next command seq after `seq`: 1..65535, skipping 0.
constexpr std::uint16_t next_command_seq(std::uint16_t seq) {
  return seq == 0xFFFF ? std::uint16_t{1} : static_cast<std::uint16_t>(seq + 1);
}

/// Registers <-> big-endian bytes (2 per register). bytes_to_registers needs an even count.
std::vector<std::uint8_t> registers_to_bytes(std::span<const std::uint16_t> registers);
std::vector<std::uint16_t> bytes_to_registers(std::span<const std::uint8_t> bytes);

}  // namespace hybridctl::protocol
