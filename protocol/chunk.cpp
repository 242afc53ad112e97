// Chunk validation, byte form and the host-side chunker.

#include "protocol/chunk.hpp"

#include <algorithm>

#include "protocol/checksums.hpp"
#include "protocol/wire.hpp"

namespace hybridctl::protocol {

std::optional<ProtocolError> validate_chunk(const Chunk& chunk, std::size_t max_payload) {
  const std::string seq = "chunk " + std::to_string(chunk.seq);
  if (chunk.seq == 0)
    return ProtocolError{ResultCode::BadValue, "chunk sequence number 0: the first chunk is 1"};
  if (chunk.first_line == 0)
    return ProtocolError{ResultCode::BadValue, seq + ": first line 0: lines are numbered from 1"};
  if (chunk.payload.empty())
    return ProtocolError{ResultCode::BadLines, seq + ": empty payload: a chunk holds at least one line"};
  const std::size_t limit = std::min(max_payload, kChunkPayloadFieldMax);
  if (chunk.payload.size() > limit)
    return ProtocolError{ResultCode::TooLong, seq + ": payload of " + std::to_string(chunk.payload.size()) +
                                                  " bytes, at most " + std::to_string(limit) + " fit"};
  std::size_t newlines = 0;
  for (std::size_t i = 0; i < chunk.payload.size(); ++i) {
    const auto b = static_cast<std::uint8_t>(chunk.payload[i]);
    if (b == 0 || b > 0x7F)
      return ProtocolError{ResultCode::BadText, seq + ": payload byte " + std::to_string(i) + " is " +
                                                    hex_byte(b) + ", expected ASCII 0x01..0x7F"};
    if (b == '\n') ++newlines;
  }
  if (chunk.payload.back() != '\n')
    return ProtocolError{ResultCode::BadLines, seq + ": payload does not end in a newline (a partial line)"};
  if (newlines != chunk.line_count)
    return ProtocolError{ResultCode::BadLines, seq + ": header says " + std::to_string(chunk.line_count) +
                                                   " lines, payload holds " + std::to_string(newlines)};
  return std::nullopt;
}

Expected<std::vector<std::uint8_t>> encode_chunk_bytes(const Chunk& chunk, std::size_t max_payload) {
  if (auto error = validate_chunk(chunk, max_payload)) return std::move(*error);
  std::vector<std::uint8_t> out;
  out.reserve(kChunkHeaderBytes + chunk.payload.size());
  put_u32(out, chunk.seq);
  put_u32(out, chunk.identity_tag);
  put_u32(out, chunk.first_line);
  put_u16(out, chunk.line_count);
  put_u16(out, static_cast<std::uint16_t>(chunk.payload.size()));
  put_u32(out, crc32(chunk.payload));
  out.insert(out.end(), chunk.payload.begin(), chunk.payload.end());
  return out;
}

std::optional<ChunkHeader> read_chunk_header(std::span<const std::uint8_t> bytes) {
  if (bytes.size() < kChunkHeaderBytes) return std::nullopt;
  ChunkHeader h;
  h.seq = get_u32(bytes, 0);
  h.identity_tag = get_u32(bytes, 4);
  h.first_line = get_u32(bytes, 8);
  h.line_count = get_u16(bytes, 12);
  h.payload_length = get_u16(bytes, 14);
  h.crc = get_u32(bytes, 16);
  return h;
}

Expected<Chunk> chunk_from_parts(const ChunkHeader& header, std::span<const std::uint8_t> payload,
                                 std::size_t max_payload) {
  const std::string seq = "chunk " + std::to_string(header.seq);
  if (payload.size() != header.payload_length)
    return ProtocolError{ResultCode::BadLength, seq + ": header says " + std::to_string(header.payload_length) +
                                                    " payload bytes, " + std::to_string(payload.size()) +
                                                    " arrived"};
  const std::size_t limit = std::min(max_payload, kChunkPayloadFieldMax);
  if (header.payload_length > limit)
    return ProtocolError{ResultCode::TooLong, seq + ": payload of " + std::to_string(header.payload_length) +
                                                  " bytes, at most " + std::to_string(limit) + " accepted"};
  const std::uint32_t crc = crc32(payload);
  if (crc != header.crc)
    return ProtocolError{ResultCode::BadCrc, seq + ": payload CRC-32 is " + hex_u32(crc) + ", header says " +
                                                 hex_u32(header.crc)};
  Chunk chunk;
  chunk.seq = header.seq;
  chunk.identity_tag = header.identity_tag;
  chunk.first_line = header.first_line;
  chunk.line_count = header.line_count;
  chunk.payload.assign(payload.begin(), payload.end());
  if (auto error = validate_chunk(chunk, max_payload)) return std::move(*error);
  return chunk;
}

Expected<Chunk> decode_chunk_bytes(std::span<const std::uint8_t> message, std::size_t max_payload) {
  const auto header = read_chunk_header(message);
  if (!header)
    return ProtocolError{ResultCode::BadLength, "chunk message of " + std::to_string(message.size()) +
                                                    " bytes, shorter than its 20-byte header"};
  const std::size_t expected = kChunkHeaderBytes + header->payload_length;
  if (message.size() != expected)
    return ProtocolError{ResultCode::BadLength,
                         "chunk " + std::to_string(header->seq) + ": message of " + std::to_string(message.size()) +
                             " bytes, header + payload length say " + std::to_string(expected)};
  return chunk_from_parts(*header, message.subspan(kChunkHeaderBytes), max_payload);
}

std::vector<std::string> program_lines(std::string_view text) {
  std::vector<std::string> lines;
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find('\n', start);
    const bool terminated = end != std::string_view::npos;
    if (!terminated) end = text.size();
    std::string_view line = text.substr(start, end - start);
    if (terminated && !line.empty() && line.back() == '\r') line.remove_suffix(1);
    lines.emplace_back(line);
    start = terminated ? end + 1 : end;
  }
  return lines;
}

std::string program_text(std::span<const std::string> lines) {
  std::size_t size = 0;
  for (const auto& l : lines) size += l.size() + 1;
  std::string text;
  text.reserve(size);
  for (const auto& l : lines) {
    text += l;
    text += '\n';
  }
  return text;
}

std::uint64_t program_identity(std::span<const std::string> lines) {
  Fnv1a64 h;
  for (const auto& l : lines) {
    h.update(l);
    h.update(std::string_view("\n"));
  }
  return h.value();
}

Expected<Chunk> make_chunk(std::span<const std::string> lines, std::uint32_t first_line, std::uint32_t seq,
                           std::uint64_t identity, std::size_t max_payload) {
  if (first_line == 0 || first_line > lines.size())
    return ProtocolError{ResultCode::BadValue, "first line " + std::to_string(first_line) +
                                                   " is outside the program's lines 1.." +
                                                   std::to_string(lines.size())};
  if (seq == 0) return ProtocolError{ResultCode::BadValue, "chunk sequence number 0: the first chunk is 1"};
  const std::size_t limit = std::min(max_payload, kChunkPayloadFieldMax);
  Chunk chunk;
  chunk.seq = seq;
  chunk.identity_tag = identity_tag(identity);
  chunk.first_line = first_line;
  for (std::size_t i = first_line - 1; i < lines.size() && chunk.line_count < 0xFFFF; ++i) {
    const std::string& line = lines[i];
    for (std::size_t col = 0; col < line.size(); ++col) {
      const auto b = static_cast<std::uint8_t>(line[col]);
      if (b == 0 || b > 0x7F || b == '\n')
        return ProtocolError{ResultCode::BadText, "line " + std::to_string(i + 1) + ", column " +
                                                      std::to_string(col + 1) + ": byte " + hex_byte(b) +
                                                      ", expected ASCII 0x01..0x7F other than newline"};
    }
    if (line.size() + 1 > limit) {
      if (chunk.line_count > 0) break;  // it gets its own (failing) chunk next time
      return ProtocolError{ResultCode::TooLong, "line " + std::to_string(i + 1) + " has " +
                                                    std::to_string(line.size()) + " bytes, a chunk carries at most " +
                                                    std::to_string(limit - 1) + " per line"};
    }
    if (chunk.payload.size() + line.size() + 1 > limit) break;
    chunk.payload += line;
    chunk.payload += '\n';
    ++chunk.line_count;
  }
  return chunk;
}

}  // namespace hybridctl::protocol
