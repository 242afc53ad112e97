// The protocol's checksums match their published check values, and the incremental forms
// agree with the one-shot ones.

#include "protocol/checksums.hpp"

#include <gtest/gtest.h>

#include <string>

namespace {

using namespace hybridctl::protocol;

TEST(Crc32, MatchesTheIeee8023CheckValue) {
  EXPECT_EQ(crc32(std::string_view("123456789")), 0xCBF43926u);
  EXPECT_EQ(crc32(std::string_view("")), 0x00000000u);
  EXPECT_EQ(crc32(std::string_view("The quick brown fox jumps over the lazy dog")), 0x414FA339u);
}

TEST(Crc32, IncrementalEqualsOneShot) {
  const std::string text = "G1 X10 Y20 F300\nG0 Z5\nM30\n";
  Crc32 crc;
  crc.update(std::string_view(text).substr(0, 7));
  crc.update(std::string_view(text).substr(7));
  EXPECT_EQ(crc.value(), crc32(text));
  const std::span<const std::uint8_t> bytes(reinterpret_cast<const std::uint8_t*>(text.data()), text.size());
  EXPECT_EQ(crc32(bytes), crc32(text));
}

TEST(Crc32, EverySingleBitFlipChangesIt) {
  std::string text = "N10 G1 X-12.5 Y3 F1200\n";
  const std::uint32_t good = crc32(text);
  for (std::size_t i = 0; i < text.size(); ++i) {
    for (int bit = 0; bit < 8; ++bit) {
      text[i] = static_cast<char>(text[i] ^ (1 << bit));
      EXPECT_NE(crc32(text), good) << "byte " << i << " bit " << bit;
      text[i] = static_cast<char>(text[i] ^ (1 << bit));
    }
  }
}

TEST(Fnv1a64, MatchesThePublishedTestVectors) {
  EXPECT_EQ(fnv1a64(""), 0xCBF29CE484222325ull);
  EXPECT_EQ(fnv1a64("a"), 0xAF63DC4C8601EC8Cull);
  EXPECT_EQ(fnv1a64("foobar"), 0x85944171F73967E8ull);
}

TEST(Fnv1a64, IncrementalEqualsOneShot) {
  Fnv1a64 h;
  h.update(std::string_view("foo"));
  h.update(std::string_view("bar"));
  EXPECT_EQ(h.value(), fnv1a64("foobar"));
}

}  // namespace
