#pragma once
// A remote CAN bus with the simulated controller on it, reached over TCP the way the
// socketcand daemon serves a bus (https://github.com/linux-can/socketcand, its raw mode):
//
//   server: < hi >                        on connect
//   client: < open CHANNEL >     server: < ok >            any channel name (1-15 of A-Z a-z 0-9 _ . -)
//   client: < rawmode >          server: < ok >            frames on the bus now go to this client
//   client: < send ID LEN B0 B1 ... >                      ID hex (11 or 29 bits), LEN 0..8, bytes hex
//   server: < frame ID SEC.USEC DATAHEX >                  ID %03X (%08X above 0x7FF), data bytes run together
//   client: < echo >             server: < echo >
//   client: < bcmmode >          server: < ok >            back to broadcast-manager mode (no frames)
//   anything else, or a malformed element:   server: < error WHAT >   (nothing is put on the bus;
//                                            WHAT never holds an angle bracket)
//
// The bus is shared: a frame a client sends reaches the controller node (sim/wire/can_node.hpp)
// and every other raw-mode client; the node's frames (status snapshots, flow control)
// reach every raw-mode client. A client gets frames only from `raw_settle` after its
// `< ok >` to rawmode, so that answer arrives alone (python-can's client compares the
// whole first read with "< ok >").
//
// Pacing: with bitrate > 0 every frame occupies the bus for can_frame_time() (worst-case
// bit stuffing) and frames are delivered one after another at that rate, in both
// directions, as on a real bus at that bit rate. bitrate 0 delivers at once.
//
// Fault injection (sim/wire/fault_injection.hpp): drop_every closes the connection of the
// client whose `< send >` is the N-th; exception_every answers the N-th chunk transfer's
// first frame with flow control OVERFLOW/ABORT; corrupt_every damages the N-th frame
// text sent to a client ("< fr@me ..."), which the client must discard, as a CAN
// controller discards a frame with a CRC error; delay_ms holds the node's frames back.

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "protocol/can_frames.hpp"
#include "sim/wire/can_node.hpp"
#include "sim/wire/fault_injection.hpp"
#include "sim/wire/serve_loop.hpp"

namespace hybridctl::sim::wire {

struct SocketcandOptions {
  CanNodeOptions node;
  FaultOptions faults;
  std::uint32_t bitrate = 0;                        ///< bus pacing, bit/s (0: none)
  std::chrono::milliseconds raw_settle{20};         ///< quiet time after "< ok >" to rawmode
  std::size_t max_clients = 16;
  std::size_t max_output_bytes = 1 << 20;           ///< a client that does not read this much is dropped
  std::uint32_t max_errors = 100;                   ///< errors in a row before a client is dropped
};

struct SocketcandCounters {
  std::uint64_t connections = 0;
  std::uint64_t refused_connections = 0;
  std::uint64_t disconnects = 0;
  std::uint64_t frames_from_hosts = 0;   ///< valid `< send >` elements
  std::uint64_t frames_to_hosts = 0;     ///< frame elements written (one per frame and client)
  std::uint64_t errors_sent = 0;         ///< `< error >` answers
  std::uint64_t garbage_disconnects = 0; ///< clients dropped after max_errors errors in a row
  std::uint64_t slow_disconnects = 0;    ///< clients dropped for not reading
};

class SocketcandServer final : public WireEndpoint {
 public:
  /// Listens on `address` (IPv4) and `port` (0: a free port). Throws hybridctl::InputError
  /// naming the address when it cannot.
  SocketcandServer(protocol::ControllerPort& controller, const std::string& address, int port, SocketcandOptions options = {});
  ~SocketcandServer() override;
  SocketcandServer(const SocketcandServer&) = delete;
  SocketcandServer& operator=(const SocketcandServer&) = delete;

  const std::string& address() const;
  int port() const;
  std::size_t client_count() const;
  const SocketcandCounters& counters() const;
  const CanNodeCounters& node_counters() const;
  const FaultCounters& faults() const;

  void collect(std::vector<pollfd>& fds) override;
  void service(std::span<const pollfd> fds, SteadyTime now) override;
  void tick(SteadyTime now) override;
  SteadyTime next_deadline() const override;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

// ---- the text protocol, exposed for tests ----

struct SocketcandRequest {
  enum class Kind { Open, RawMode, BcmMode, Echo, Send };
  Kind kind = Kind::Echo;
  std::string channel;              ///< Open
  protocol::can::CanFrame frame;    ///< Send
};

struct SocketcandParse {
  std::optional<SocketcandRequest> request;
  std::string error;  ///< set when the element is refused: what was wrong and what was expected
};

/// Parses one element, "<" to ">" inclusive.
SocketcandParse parse_socketcand_element(std::string_view element);

/// One piece of a client's stream, as the server splits it.
struct SocketcandPiece {
  enum class Kind {
    Element,   ///< "<" to the next ">", with no "<" between
    Garbage,   ///< text outside an element, up to the next "<" (whitespace is skipped)
    Unclosed,  ///< "<" up to (not including) another "<" that comes before any ">"
    Overlong,  ///< an element still open after max_element bytes: the rest of the input
  };
  Kind kind;
  std::string_view text;
};

/// Splits the complete pieces at the front of `in` (a client's stream so far), calling
/// `on_piece` for each until it returns false; returns how many bytes of `in` were used.
/// An element not yet closed at the end waits for more input (not used), unless it is
/// already longer than `max_element`.
std::size_t split_socketcand_stream(std::string_view in, std::size_t max_element,
                                   const std::function<bool(const SocketcandPiece&)>& on_piece);

/// "< frame ID SEC.USEC DATAHEX >" for a frame received at wall-clock time sec.usec.
std::string format_socketcand_frame(const protocol::can::CanFrame& frame, long sec, long usec);

}  // namespace hybridctl::sim::wire
