#pragma once
// Chunks: numbered pieces of whole G-code lines, the unit of the program stream
// (docs/protocol.md, "Chunks"). This file holds the chunk type, its byte form (the CAN
// data message; the Modbus mailbox carries the same bytes in registers), its validation,
// and the host-side helpers that turn a program text into lines, an identity and chunks.
//
// Byte form, all integers big-endian:
//   offset 0  uint32 seq            1 for the first chunk of a program
//   offset 4  uint32 identity tag   low 32 bits of the program identity
//   offset 8  uint32 first line     1-based line number in the program of the first line
//   offset 12 uint16 line count     lines in the payload (>= 1)
//   offset 14 uint16 payload length bytes (>= 1)
//   offset 16 uint32 CRC-32         of the payload bytes
//   offset 20 payload               ASCII 0x01..0x7F, each line ending in '\n'

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "protocol/codes.hpp"

namespace hybridctl::protocol {

inline constexpr std::size_t kChunkHeaderBytes = 20;
/// The payload length field is 16 bits; transports allow less (see modbus_map.hpp, can_transfer.hpp).
inline constexpr std::size_t kChunkPayloadFieldMax = 65535;

struct Chunk {
  std::uint32_t seq = 0;           ///< chunk sequence number, first chunk is 1
  std::uint32_t identity_tag = 0;  ///< identity_tag(program identity)
  std::uint32_t first_line = 0;    ///< 1-based global line number of the payload's first line
  std::uint16_t line_count = 0;    ///< lines in the payload
  std::string payload;             ///< the lines, each ending in '\n'
  // The payload length and CRC-32 are derived from `payload` when encoding and checked
  // against it when decoding.

  friend bool operator==(const Chunk&, const Chunk&) = default;
};

/// The header fields as they travel (decoded, not yet checked against a payload).
struct ChunkHeader {
  std::uint32_t seq = 0;
  std::uint32_t identity_tag = 0;
  std::uint32_t first_line = 0;
  std::uint16_t line_count = 0;
  std::uint16_t payload_length = 0;
  std::uint32_t crc = 0;
};

/// The tag a chunk carries for a program identity: its low 32 bits.
constexpr std::uint32_t identity_tag(std::uint64_t identity) {
  return static_cast<std::uint32_t>(identity & 0xFFFFFFFFull);
}

/// Checks what a chunk says about itself (not its place in the stream):
///   seq >= 1 and first_line >= 1 (BAD_VALUE); 1 <= payload size <= max_payload (BAD_LINES for
///   empty, TOO_LONG); bytes 0x01..0x7F (BAD_TEXT, with the byte's offset); line_count equals the
///   number of '\n' and the payload ends in '\n' (BAD_LINES).
/// nullopt when valid.
std::optional<ProtocolError> validate_chunk(const Chunk& chunk, std::size_t max_payload);

/// Header + payload bytes. Refuses (returns the error) a chunk validate_chunk refuses.
Expected<std::vector<std::uint8_t>> encode_chunk_bytes(const Chunk& chunk, std::size_t max_payload);

/// Reads the 20 header bytes (nullopt if fewer are given). No checks.
std::optional<ChunkHeader> read_chunk_header(std::span<const std::uint8_t> bytes);

/// Decodes header + payload. The message must be exactly 20 + payload length bytes
/// (BAD_LENGTH), the payload length at most max_payload (TOO_LONG), the CRC must match
/// (BAD_CRC), then validate_chunk applies.
Expected<Chunk> decode_chunk_bytes(std::span<const std::uint8_t> message, std::size_t max_payload);

/// Checks a decoded header and its payload bytes (shared by the byte and register decoders).
Expected<Chunk> chunk_from_parts(const ChunkHeader& header, std::span<const std::uint8_t> payload,
                                 std::size_t max_payload);

// ---- host side: program text -> lines -> identity -> chunks ----

/// Splits a program text into lines: on '\n', dropping one '\r' before it; a last line
/// without '\n' counts, the empty rest after a final '\n' does not. Lines keep everything
/// else (comments, '%', blanks): the controller sees the program as written.
std::vector<std::string> program_lines(std::string_view text);

/// The program text as streamed: every line followed by '\n'.
std::string program_text(std::span<const std::string> lines);

/// The program identity: FNV-1a 64 of program_text(lines).
std::uint64_t program_identity(std::span<const std::string> lines);

/// The chunk `seq` holding as many whole lines as fit in max_payload bytes, starting at
/// 1-based line `first_line` of `lines` (at most 65535 lines). Errors: first_line outside
/// 1..lines.size() (BAD_VALUE); a line with a NUL, a byte above 0x7F or a '\n' (BAD_TEXT); a
/// line longer than max_payload - 1 bytes (TOO_LONG); each names the line.
Expected<Chunk> make_chunk(std::span<const std::string> lines, std::uint32_t first_line,
                           std::uint32_t seq, std::uint64_t identity, std::size_t max_payload);

}  // namespace hybridctl::protocol
