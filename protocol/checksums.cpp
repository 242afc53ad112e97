// CRC-32 by a 256-entry table built at compile time; FNV-1a 64 is common/hash.hpp.

#include "protocol/checksums.hpp"

#include <array>

namespace hybridctl::protocol {
namespace {

constexpr std::array<std::uint32_t, 256> make_crc_table() {
  std::array<std::uint32_t, 256> table{};
  for (std::uint32_t i = 0; i < 256; ++i) {
    std::uint32_t c = i;
    for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    table[i] = c;
  }
  return table;
}

constexpr auto kCrcTable = make_crc_table();

}  // namespace

void Crc32::update(std::span<const std::uint8_t> bytes) {
  for (std::uint8_t b : bytes) state_ = kCrcTable[(state_ ^ b) & 0xFFu] ^ (state_ >> 8);
}

void Crc32::update(std::string_view text) {
  for (char c : text) state_ = kCrcTable[(state_ ^ static_cast<std::uint8_t>(c)) & 0xFFu] ^ (state_ >> 8);
}

std::uint32_t crc32(std::span<const std::uint8_t> bytes) {
  Crc32 crc;
  crc.update(bytes);
  return crc.value();
}

std::uint32_t crc32(std::string_view text) {
  Crc32 crc;
  crc.update(text);
  return crc.value();
}

}  // namespace hybridctl::protocol
