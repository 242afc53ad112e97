#pragma once
// The two checksums of the program-stream protocol:
//   CRC-32 (IEEE 802.3: reflected polynomial 0xEDB88320, init and final xor 0xFFFFFFFF) of
//     each chunk's payload; "123456789" -> 0xCBF43926.
//   FNV-1a 64 (offset basis 0xCBF29CE484222325, prime 0x100000001B3) of the whole program
//     text: the program identity; "a" -> 0xAF63DC4C8601EC8C.
// Both have an incremental form for data that arrives in pieces.

#include <cstdint>
#include <span>
#include <string_view>

#include "common/hash.hpp"

namespace hybridctl::protocol {

class Crc32 {
 public:
  void update(std::span<const std::uint8_t> bytes);
  void update(std::string_view text);
  std::uint32_t value() const { return ~state_; }

 private:
  std::uint32_t state_ = 0xFFFFFFFFu;
};

std::uint32_t crc32(std::span<const std::uint8_t> bytes);
std::uint32_t crc32(std::string_view text);

// The program identity's hash is the project's one (common/hash.hpp).
using hybridctl::Fnv1a64;
using hybridctl::fnv1a64;

}  // namespace hybridctl::protocol
