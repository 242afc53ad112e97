#pragma once
// Byte and register packing shared by the protocol's encoders and decoders: big-endian
// bytes, most significant 16-bit word first in registers, hex for messages. Callers check
// sizes before reading; these helpers do not.

#include <cstdint>
#include <cstdio>
#include <span>
#include <string>
#include <vector>

namespace hybridctl::protocol {

inline void put_u16(std::vector<std::uint8_t>& out, std::uint16_t v) {
  out.push_back(static_cast<std::uint8_t>(v >> 8));
  out.push_back(static_cast<std::uint8_t>(v));
}
inline void put_u32(std::vector<std::uint8_t>& out, std::uint32_t v) {
  put_u16(out, static_cast<std::uint16_t>(v >> 16));
  put_u16(out, static_cast<std::uint16_t>(v));
}
inline std::uint16_t get_u16(std::span<const std::uint8_t> in, std::size_t at) {
  return static_cast<std::uint16_t>((in[at] << 8) | in[at + 1]);
}
inline std::uint32_t get_u32(std::span<const std::uint8_t> in, std::size_t at) {
  return (static_cast<std::uint32_t>(get_u16(in, at)) << 16) | get_u16(in, at + 2);
}

// Registers: 32-bit values high word first, 64-bit values most significant word first.
inline void set_u32(std::span<std::uint16_t> regs, std::size_t at, std::uint32_t v) {
  regs[at] = static_cast<std::uint16_t>(v >> 16);
  regs[at + 1] = static_cast<std::uint16_t>(v);
}
inline void set_u64(std::span<std::uint16_t> regs, std::size_t at, std::uint64_t v) {
  set_u32(regs, at, static_cast<std::uint32_t>(v >> 32));
  set_u32(regs, at + 2, static_cast<std::uint32_t>(v));
}
inline std::uint32_t reg_u32(std::span<const std::uint16_t> regs, std::size_t at) {
  return (static_cast<std::uint32_t>(regs[at]) << 16) | regs[at + 1];
}
inline std::uint64_t reg_u64(std::span<const std::uint16_t> regs, std::size_t at) {
  return (static_cast<std::uint64_t>(reg_u32(regs, at)) << 32) | reg_u32(regs, at + 2);
}

inline std::string hex_byte(std::uint8_t b) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "0x%02X", b);
  return buf;
}
inline std::string hex_u32(std::uint32_t v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%08X", v);
  return buf;
}
inline std::string hex_id(std::uint32_t v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%03X", v);
  return buf;
}

}  // namespace hybridctl::protocol
