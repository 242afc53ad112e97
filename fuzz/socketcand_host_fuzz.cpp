// Fuzz target: the host side of socketcand's text protocol (drivers/socketcand_transport.hpp):
// the byte-stream reader (SocketcandReader) fed the input in arbitrary pieces, and every
// element it yields read as a frame (parse_socketcand_frame), as SocketcandIo::receive does
// with what the daemon sends.
//
// Input: byte 0 seeds the piece sizes; the rest is the stream.
// Contract: nothing throws; no element is longer than kMaxElement; every byte fed is
// either in an element or counted as garbage; a frame it accepts has at most 8 bytes and
// an identifier of at most 29 bits, and its `< send >` form (format_socketcand_send) names
// the same identifier and bytes.

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "drivers/socketcand_transport.hpp"
#include "fuzz/fuzz_check.hpp"

namespace drivers = hybridctl::drivers;

namespace {

void check_frame(const std::vector<std::string>& words) {
  const drivers::SocketcandFrame parsed = drivers::parse_socketcand_frame(words);
  if (!parsed.frame) {
    FUZZ_CHECK(!parsed.error.empty(), "a refused element says why");
    return;
  }
  const auto& frame = *parsed.frame;
  FUZZ_CHECK(frame.len <= 8, "a frame has at most 8 bytes");
  FUZZ_CHECK(frame.id <= 0x1FFFFFFF, "an identifier has at most 29 bits");
  FUZZ_CHECK(parsed.extended || frame.id <= 0x7FF, "an 11-bit frame has an 11-bit identifier");
  // The frame as the host would send it: "< send ID LEN B0 .. >", read back word by word.
  drivers::SocketcandReader reader;
  reader.feed(drivers::format_socketcand_send(frame));
  const auto send = reader.next();
  FUZZ_CHECK(send && send->size() == 3u + frame.len && (*send)[0] == "send", "a frame formats as one send element");
  FUZZ_CHECK(std::stoul((*send)[1], nullptr, 16) == frame.id, "send names the frame's identifier");
  FUZZ_CHECK(std::stoul((*send)[2]) == frame.len, "send names the frame's length");
  for (std::size_t i = 0; i < frame.len; ++i)
    FUZZ_CHECK(std::stoul((*send)[3 + i], nullptr, 16) == frame.data[i], "send carries the frame's bytes");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  std::uint32_t piece_seed = data[0] * 2654435761u + 1;
  const std::string_view stream(reinterpret_cast<const char*>(data + 1), size - 1);

  drivers::SocketcandReader reader;
  std::size_t fed = 0, in_elements = 0;
  while (fed < stream.size()) {
    piece_seed = piece_seed * 1103515245u + 12345u;
    const std::size_t piece = 1 + (piece_seed >> 16) % 97;
    const std::string_view chunk = stream.substr(fed, piece);
    reader.feed(chunk);
    fed += chunk.size();
    while (auto words = reader.next()) {
      std::size_t characters = 0;
      for (const auto& w : *words) {
        FUZZ_CHECK(!w.empty(), "words are not empty");
        FUZZ_CHECK(w.find_first_of("<> \t\r\n\v\f") == std::string::npos, "words hold no brackets or spaces");
        characters += w.size();
      }
      FUZZ_CHECK(characters + 2 <= drivers::SocketcandReader::kMaxElement, "no element is over-long");
      in_elements += characters;
      check_frame(*words);
    }
  }
  FUZZ_CHECK(reader.garbage_bytes() + in_elements <= fed, "no byte is counted twice");
  return 0;
}
