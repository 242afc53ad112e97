// Fuzz target: the simulator's side of socketcand's text protocol (sim/wire/socketcand_server.hpp):
// the input split into elements by the server's own split_socketcand_stream (text outside
// `< >` and unclosed elements are errors), each parsed by parse_socketcand_element; and
// the two sides against each other: a `< send >` frame the server accepts, written back as
// the server's `< frame >` element (format_socketcand_frame), must read the same on the
// host (drivers: SocketcandReader, parse_socketcand_frame), and the host's `< send >` form
// of it must parse the same on the server.
// Contract: nothing throws; a refused element gets an error text that can stand inside
// `< error ... >` (no angle brackets, no line breaks).

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "drivers/socketcand_transport.hpp"
#include "fuzz/fuzz_check.hpp"
#include "sim/wire/socketcand_server.hpp"

namespace can = hybridctl::protocol::can;
namespace drivers = hybridctl::drivers;
namespace sim = hybridctl::sim;

namespace {

bool same_frame(const can::CanFrame& a, const can::CanFrame& b) { return a == b; }

void check_element(std::string_view element) {
  const sim::wire::SocketcandParse p = sim::wire::parse_socketcand_element(element);
  if (!p.request) {
    FUZZ_CHECK(!p.error.empty(), "a refused element says why");
    FUZZ_CHECK(p.error.find_first_of("<>\r\n") == std::string::npos, "an error text fits in < error ... >");
    return;
  }
  FUZZ_CHECK(p.error.empty(), "an accepted element has no error");
  if (p.request->kind != sim::wire::SocketcandRequest::Kind::Send) return;
  const can::CanFrame& frame = p.request->frame;
  FUZZ_CHECK(frame.len <= 8 && frame.id <= 0x1FFFFFFF, "a sent frame is a CAN frame");

  // Server -> host: the frame element every raw-mode client gets.
  drivers::SocketcandReader reader;
  reader.feed(sim::wire::format_socketcand_frame(frame, 1700000000, 123456));
  const auto words = reader.next();
  FUZZ_CHECK(words.has_value(), "the server's frame element is one element");
  const drivers::SocketcandFrame host = drivers::parse_socketcand_frame(*words);
  FUZZ_CHECK(host.frame && same_frame(*host.frame, frame), "the host reads the frame the server wrote");
  FUZZ_CHECK(host.extended == (frame.id > 0x7FF), "29-bit identifiers are marked as such");

  // Host -> server: the host's send element for the same frame.
  const sim::wire::SocketcandParse back = sim::wire::parse_socketcand_element(drivers::format_socketcand_send(frame));
  FUZZ_CHECK(back.request && back.request->kind == sim::wire::SocketcandRequest::Kind::Send &&
                 same_frame(back.request->frame, frame),
             "the server reads the frame the host sent");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view in(reinterpret_cast<const char*>(data), size);
  // The server's own split of a client's stream (split_socketcand_stream, what
  // SocketcandServer reads a client with): pieces lie inside the input, in order, and every
  // element is checked.
  const char* last_end = in.data();
  const std::size_t used = sim::wire::split_socketcand_stream(in, 256, [&](const sim::wire::SocketcandPiece& piece) {
    FUZZ_CHECK(piece.text.data() >= last_end && piece.text.data() + piece.text.size() <= in.data() + in.size(),
               "pieces lie inside the input, in order");
    FUZZ_CHECK(!piece.text.empty(), "no empty piece");
    last_end = piece.text.data() + piece.text.size();
    if (piece.kind == sim::wire::SocketcandPiece::Kind::Element) {
      FUZZ_CHECK(piece.text.front() == '<' && piece.text.back() == '>', "an element is bracketed");
      check_element(piece.text);
    }
    return true;
  });
  FUZZ_CHECK(used <= in.size(), "the split uses at most the input");
  FUZZ_CHECK(used == in.size() || in[used] == '<', "what waits for more input is an element's start");
  // Each input is also one element as a whole, brackets or not.
  check_element(in);
  return 0;
}
