#pragma once
// The program-stream protocol on Modbus (TCP and RTU): register addresses and counts, the
// chunk mailbox's register form, and the check a controller applies to each request PDU.
// Pure code: register arrays in, register arrays out; the transports (drivers/) and the
// simulator (sim/) call libmodbus themselves. docs/protocol.md, "Modbus mapping", is the
// specification.
//
// Addresses are 0-based protocol addresses, as libmodbus takes them. mbpoll's -r is
// 1-based: -r (address + 1), or -0 -r address.
//
//   holding registers (FC3 read, FC6/FC16 write, FC23 read/write)
//     0          heartbeat (host bumps it at least every 250 ms)
//     1..7       reserved (read 0; writes refused with exception 02)
//     8..15      command block (messages.hpp, command_reg)
//     16..136    chunk mailbox: 10 header registers + up to 111 payload registers
//     200..245   status mirror: the status block again, read-only, so FC23 can write the
//                mailbox (or command, or heartbeat) and read the status in one request
//   input registers (FC4 read)
//     0..45      status block (messages.hpp, status_reg)

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "protocol/chunk.hpp"
#include "protocol/messages.hpp"

namespace hybridctl::protocol::modbus {

// Modbus application protocol limits (registers per request).
inline constexpr std::size_t kMaxReadRegisters = 125;       ///< FC3, FC4
inline constexpr std::size_t kMaxWriteRegisters = 123;      ///< FC16
inline constexpr std::size_t kMaxReadWriteWrite = 121;      ///< FC23, write part
inline constexpr std::size_t kMaxReadWriteRead = 125;       ///< FC23, read part

// Holding registers.
inline constexpr std::uint16_t kHeartbeatAddress = 0;
inline constexpr std::uint16_t kCommandAddress = 8;
inline constexpr std::uint16_t kCommandCount = kCommandRegisters;  // 8
inline constexpr std::uint16_t kMailboxAddress = 16;
inline constexpr std::uint16_t kMailboxHeaderRegisters = kChunkHeaderBytes / 2;  // 10
/// The whole mailbox: one FC23 write (the smallest of the write limits).
inline constexpr std::uint16_t kMailboxRegisters = kMaxReadWriteWrite;  // 121
inline constexpr std::uint16_t kStatusMirrorAddress = 200;
inline constexpr std::uint16_t kHoldingRegisterCount = kStatusMirrorAddress + kStatusRegisters;  // 246

// Input registers.
inline constexpr std::uint16_t kStatusAddress = 0;
inline constexpr std::uint16_t kStatusCount = kStatusRegisters;  // 46
inline constexpr std::uint16_t kInputRegisterCount = kStatusCount;

/// Largest chunk payload over Modbus: what fits in the mailbox after the header.
inline constexpr std::size_t kMaxChunkPayload = 2 * (kMailboxRegisters - kMailboxHeaderRegisters);  // 222

static_assert(kMailboxRegisters <= kMaxWriteRegisters && kMailboxRegisters <= kMaxReadWriteWrite);
static_assert(kStatusCount <= kMaxReadRegisters && kStatusCount <= kMaxReadWriteRead);
static_assert(kCommandAddress + kCommandCount <= kMailboxAddress);
static_assert(kMailboxAddress + kMailboxRegisters <= kStatusMirrorAddress);
static_assert(kMaxChunkPayload == 222);

/// Registers a mailbox write of a payload of `payload_bytes` bytes takes.
constexpr std::size_t mailbox_registers_for(std::size_t payload_bytes) {
  return kMailboxHeaderRegisters + (payload_bytes + 1) / 2;
}

/// The mailbox registers for a chunk: header (seq, identity tag, first line: 2 registers
/// each, high word first; line count; payload length; CRC-32: 2 registers), then the
/// payload, two bytes per register, the first in the high byte; an odd last byte has a 0
/// low byte. Exactly mailbox_registers_for(payload) registers. Refuses a chunk
/// validate_chunk refuses, including a payload over max_payload (at most kMaxChunkPayload).
Expected<std::vector<std::uint16_t>> encode_mailbox(const Chunk& chunk,
                                                    std::size_t max_payload = kMaxChunkPayload);

/// Decodes a mailbox write. Needs at least the header and the payload's registers
/// (BAD_LENGTH); registers after them are ignored (so a controller may pass the whole
/// mailbox region). The payload length must be at most max_payload (TOO_LONG; capped at
/// kMaxChunkPayload), the pad byte 0 (BAD_LENGTH), the CRC right (BAD_CRC); then
/// validate_chunk applies.
Expected<Chunk> decode_mailbox(std::span<const std::uint16_t> registers,
                               std::size_t max_payload = kMaxChunkPayload);

// ---- the controller's view of a request ----

/// Modbus exception codes a controller answers with.
enum class ModbusException : std::uint8_t {
  IllegalFunction = 1,     ///< function code not served
  IllegalDataAddress = 2,  ///< outside the map, or not a whole block
  IllegalDataValue = 3,    ///< malformed request (counts, byte count, length)
};

/// Which block a write addresses.
enum class WriteTarget { None, Heartbeat, Command, Mailbox };

/// A request PDU (function code first, no MBAP header, no RTU address or CRC).
struct ModbusRequest {
  std::uint8_t function = 0;      ///< 3, 4, 6, 16 or 23
  std::uint16_t read_address = 0; ///< FC3, FC4, FC23
  std::uint16_t read_count = 0;
  std::uint16_t write_address = 0;  ///< FC6, FC16, FC23
  std::vector<std::uint16_t> values;  ///< written values (one for FC6)
};

struct ModbusRequestVerdict {
  std::optional<ModbusRequest> request;       ///< set when the PDU parsed
  WriteTarget target = WriteTarget::None;     ///< the block a write addresses
  std::optional<ModbusException> exception;   ///< set: answer with it and change nothing
  std::string message;                        ///< why, for the log
};

/// Parses a request PDU and checks it against the map:
///   FC3 reads holding registers inside 0..245; FC4 input registers inside 0..45;
///   writes (FC6, FC16, and FC23's write part) address exactly one block: the heartbeat
///   (address 0, 1 register), the command block (address 8, 8 registers) or the mailbox
///   (address 16, 1..121 registers); anything else is exception 02. FC23's read part is
///   checked like FC3. Malformed PDUs (length, byte count, counts above the Modbus limits or
///   0) are exception 03; other function codes exception 01.
/// A controller applies a write that passes (decoding the block from `values`, not from its
/// register mapping), updates its status block and mirror, and only then builds the reply,
/// so an FC23 reply carries the status after the write.
ModbusRequestVerdict inspect_request_pdu(std::span<const std::uint8_t> pdu);

}  // namespace hybridctl::protocol::modbus
