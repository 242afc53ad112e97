// socketcand's text protocol on the host side: the element reader, the frame parser and the
// send format (drivers/socketcand_transport.hpp). Garbage never crashes and never passes
// for a frame.

#include <gtest/gtest.h>

#include <random>

#include "drivers/socketcand_transport.hpp"

namespace hybridctl::test {
namespace {

using drivers::parse_socketcand_frame;
using drivers::SocketcandReader;
using Words = std::vector<std::string>;

std::vector<Words> all(SocketcandReader& r) {
  std::vector<Words> out;
  while (auto w = r.next()) out.push_back(*w);
  return out;
}

TEST(SocketcandText, SplitsElementsWhateverTheReadBoundaries) {
  const std::string stream = "< hi >< ok >\n< frame 181 1700000000.123456 0001000100000000 >< frame 281 1.5 30080000 >";
  const std::vector<Words> expected = {{"hi"},
                                       {"ok"},
                                       {"frame", "181", "1700000000.123456", "0001000100000000"},
                                       {"frame", "281", "1.5", "30080000"}};
  // All at once, and one byte at a time.
  SocketcandReader whole;
  whole.feed(stream);
  EXPECT_EQ(all(whole), expected);
  SocketcandReader bytewise;
  std::vector<Words> got;
  for (char c : stream) {
    bytewise.feed(std::string_view(&c, 1));
    for (auto& w : all(bytewise)) got.push_back(w);
  }
  EXPECT_EQ(got, expected);
  EXPECT_EQ(bytewise.garbage_bytes(), 1u);  // the newline between elements
}

TEST(SocketcandText, SkipsGarbageAndDamagedElements) {
  SocketcandReader r;
  r.feed("junk< fr<me 181 1.0 00 >tail< frame 181 1.0 0102 >");
  const auto words = all(r);
  ASSERT_EQ(words.size(), 2u);
  EXPECT_EQ(words[0], (Words{"me", "181", "1.0", "00"}));  // the damaged start is dropped; its rest is not a frame
  EXPECT_EQ(words[1], (Words{"frame", "181", "1.0", "0102"}));
  EXPECT_FALSE(parse_socketcand_frame(words[0]).frame);
  EXPECT_EQ(r.garbage_bytes(), 4u + 4u + 4u);  // "junk", "< fr", "tail"
}

TEST(SocketcandText, DropsAnElementThatNeverEnds) {
  SocketcandReader r;
  r.feed("< frame " + std::string(1000, 'A'));
  EXPECT_FALSE(r.next());
  EXPECT_GE(r.garbage_bytes(), 1000u);
  r.feed("< ok >");
  auto w = r.next();
  ASSERT_TRUE(w);
  EXPECT_EQ(*w, (Words{"ok"}));
  SocketcandReader empty;
  empty.feed("<   >");
  auto e = empty.next();
  ASSERT_TRUE(e);
  EXPECT_TRUE(e->empty());
}

TEST(SocketcandText, ParsesFrames) {
  auto f = parse_socketcand_frame(Words{"frame", "181", "1700000000.000001", "00FFa0"});
  ASSERT_TRUE(f.frame) << f.error;
  EXPECT_FALSE(f.extended);
  EXPECT_EQ(f.frame->id, 0x181u);
  EXPECT_EQ(f.frame->len, 3);
  EXPECT_EQ(f.frame->data[1], 0xFF);
  EXPECT_EQ(f.frame->data[2], 0xA0);
  // No data bytes: the data word is absent.
  f = parse_socketcand_frame(Words{"frame", "7FF", "12.5"});
  ASSERT_TRUE(f.frame) << f.error;
  EXPECT_EQ(f.frame->len, 0);
  // 29-bit identifiers come with 8 digits.
  f = parse_socketcand_frame(Words{"frame", "00000181", "1.0", "00"});
  ASSERT_TRUE(f.frame);
  EXPECT_TRUE(f.extended);
  for (const Words& bad : std::vector<Words>{
           {"frame", "181", "1.0", "0"},                    // odd digits
           {"frame", "181", "1.0", "000102030405060708"},   // 9 bytes
           {"frame", "18G", "1.0", "00"},                   // not hex
           {"frame", "123456789", "1.0", "00"},             // 9 digits
           {"frame", "3FFFFFFF", "1.0", "00"},              // above 29 bits
           {"frame", "181", "1.x", "00"},                   // time
           {"frame", "181", "-1.0", "00"},
           {"frame", "181", "1.0", "00", "extra"},
           {"frame", "181"},
           {"frame", "181", "1.0", "0g"},
           {"error", "bad", "thing"},
           {}}) {
    const auto r = parse_socketcand_frame(bad);
    EXPECT_FALSE(r.frame) << "accepted a bad frame element of " << bad.size() << " words";
    EXPECT_FALSE(r.error.empty());
  }
}

TEST(SocketcandText, FormatsSendsAsSocketcandReadsThem) {
  protocol::can::CanFrame f;
  f.id = 0x201;
  f.len = 8;
  const std::uint8_t bytes[8] = {0x10, 0x0E, 0x01, 0x00, 0x00, 0x00, 0x01, 0xAB};
  std::copy(bytes, bytes + 8, f.data);
  EXPECT_EQ(drivers::format_socketcand_send(f), "< send 201 8 10 E 1 0 0 0 1 AB >");
  f.id = 0x701;
  f.len = 0;
  EXPECT_EQ(drivers::format_socketcand_send(f), "< send 701 0 >");
}

TEST(SocketcandText, RandomBytesAndMutatedStreamsNeverCrashOrForgeFrames) {
  std::mt19937 rng(20261125);
  const std::string valid = "< frame 181 1.000001 0001020304050607 >";
  for (int round = 0; round < 2000; ++round) {
    std::string s;
    const int pieces = 1 + static_cast<int>(rng() % 20);
    for (int p = 0; p < pieces; ++p) {
      if (rng() % 2) {
        s += valid;
      } else {
        const int n = static_cast<int>(rng() % 40);
        for (int k = 0; k < n; ++k) s += static_cast<char>(rng() % 256);
      }
    }
    // Mutate some bytes.
    for (int m = static_cast<int>(rng() % 4); m > 0 && !s.empty(); --m) s[rng() % s.size()] = static_cast<char>(rng() % 256);
    SocketcandReader r;
    std::size_t at = 0;
    while (at < s.size()) {
      const std::size_t n = std::min<std::size_t>(s.size() - at, 1 + rng() % 64);
      r.feed(std::string_view(s).substr(at, n));
      at += n;
      while (auto w = r.next()) {
        const auto f = parse_socketcand_frame(*w);
        if (f.frame) {
          ASSERT_LE(f.frame->len, 8);
          ASSERT_LE(f.frame->id, 0x1FFFFFFFu);
        }
      }
    }
  }
}

}  // namespace
}  // namespace hybridctl::test
