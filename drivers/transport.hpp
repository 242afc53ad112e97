#pragma once
// A connection to a controller that speaks the program-stream protocol
// (docs/protocol.md), whatever carries it: Modbus TCP or RTU (libmodbus), socketcand (CAN
// over a TCP text protocol), or kernel SocketCAN. One interface; the backend comes from
// the transport URI (config/transport_uri.hpp):
//
//   auto t = drivers::open_transport("modbus-tcp://127.0.0.1:1502?unit=1");
//   protocol::Status s = t->read_status();
//   s = t->send_chunk(chunk);            // the chunk, then the status after it
//
// Every call either completes or throws TransportError; a backend reconnects by itself
// (with backoff, up to TransportOptions::reconnect_attempts) before giving up, and counts
// what went wrong. Not thread-safe: one Transport per thread (libmodbus contexts are not).

#include <chrono>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>

#include <string_view>

#include "protocol/chunk.hpp"
#include "protocol/messages.hpp"

namespace hybridctl::config {
struct Transport;
}

namespace hybridctl::drivers {

class TransportError : public std::runtime_error {
 public:
  enum class Kind {
    Unreachable,   // cannot connect (after the reconnect attempts)
    Timeout,       // no (valid) reply in time
    Disconnected,  // the connection broke mid-request
    Protocol,      // the reply did not decode (a corrupt frame, a Modbus exception)
    Unsupported,   // the transport cannot run here (e.g. no AF_CAN in this kernel)
  };
  TransportError(Kind kind, const std::string& what) : std::runtime_error(what), kind_(kind) {}
  Kind kind() const { return kind_; }

 private:
  Kind kind_;
};

// "unreachable", "timeout", "disconnected", "protocol", "unsupported".
std::string_view to_string(TransportError::Kind kind);

struct TransportOptions {
  std::chrono::milliseconds response_timeout{500};
  int reconnect_attempts = 10;                      // per call, before TransportError
  std::chrono::milliseconds reconnect_backoff{50};  // doubled after each failure, up to 2 s
  int request_retries = 3;                          // resends of a request after a timeout or bad reply
};

// What went wrong so far, for the run report and the log.
struct TransportCounters {
  std::uint64_t requests = 0;
  std::uint64_t timeouts = 0;
  std::uint64_t bad_replies = 0;   // corrupt frames, unexpected exceptions
  std::uint64_t reconnects = 0;
  std::uint64_t retries = 0;
};

class Transport {
 public:
  virtual ~Transport() = default;
  // "modbus-tcp 127.0.0.1:1502 unit 1", for messages.
  virtual std::string describe() const = 0;
  // The largest chunk payload this transport carries in one transfer.
  virtual std::size_t max_chunk_payload() const = 0;

  virtual protocol::Status read_status() = 0;
  // Writes the command block (or frames), then returns the status read after it.
  virtual protocol::Status send_command(const protocol::Command& command) = 0;
  // Sends one chunk (Modbus: FC23 mailbox write + status read in one request), then
  // returns the status after it. Chunk-level results are in the status (chunk_result).
  virtual protocol::Status send_chunk(const protocol::Chunk& chunk) = 0;
  virtual void send_heartbeat(std::uint16_t counter) = 0;

  virtual TransportCounters counters() const = 0;
};

// Opens (and connects) the backend for `uri`. Throws TransportError (Unreachable,
// Unsupported) and hybridctl::InputError for a malformed URI.
std::unique_ptr<Transport> open_transport(const std::string& uri, const TransportOptions& options = {});
// The same for a transport already parsed (config::parse_transport_uri, a machine file's
// `transports`). Throws InputError for settings the backend cannot use (e.g. a baud rate
// libmodbus does not know, which it would silently turn into 9600).
std::unique_ptr<Transport> open_transport(const config::Transport& where, const TransportOptions& options = {});

}  // namespace hybridctl::drivers
