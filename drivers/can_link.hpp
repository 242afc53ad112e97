#pragma once
// The program-stream protocol on a classic CAN bus (docs/protocol.md, "CAN mapping"), the
// part shared by the kernel SocketCAN and the socketcand backends. A CanFrameIo moves
// frames; CanTransport speaks the protocol over it:
//
//   read_status     the newest status snapshot (0x180 + N, 16 frames) that arrived since
//                   the last one a call returned; if none, the next one to complete (the
//                   controller sends one at least every 100 ms and on every state change)
//   send_command    the command frames (0x100 + N), then the first snapshot whose
//                   command_seq is the command's seq
//   send_chunk      the chunk message segmented on 0x200 + N by protocol::can::CanSegmenter,
//                   paced by the controller's flow control (0x280 + N); then the first
//                   snapshot completed after the last frame whose last_written_chunk is the
//                   chunk's seq
//   send_heartbeat  one frame on 0x700 + N
//
// A call that sees no fitting snapshot within response_timeout, or whose transfer the
// controller refuses (flow control overflow/abort) or lets time out, resends (at most
// request_retries times): a chunk received twice is a DUPLICATE, a command's seq makes a
// repeat a no-op. A broken connection is reopened with backoff (reconnect_attempts,
// doubling from reconnect_backoff up to 2 s) and the call resent.

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>

#include "protocol/can_frames.hpp"
#include "protocol/can_transfer.hpp"
#include "drivers/transport.hpp"

namespace hybridctl::drivers {

using SteadyClock = std::chrono::steady_clock;
using SteadyTime = SteadyClock::time_point;

/// Moves classic CAN frames to and from one bus: what differs between the backends.
class CanFrameIo {
 public:
  virtual ~CanFrameIo() = default;
  /// "socketcand 127.0.0.1:29536 channel can0", for messages.
  virtual std::string describe() const = 0;
  /// Opens the connection within `timeout`. Throws TransportError: Unreachable (may work
  /// later: the caller retries with backoff), Unsupported or Protocol (will not work: the
  /// caller gives up at once).
  virtual void open(std::chrono::milliseconds timeout) = 0;
  virtual void close() = 0;
  virtual bool is_open() const = 0;
  /// Puts the frames on the bus in order. Throws TransportError(Disconnected).
  virtual void send(std::span<const protocol::can::CanFrame> frames) = 0;
  /// The next frame from the bus, waiting until `deadline` at most (a deadline in the past:
  /// only what already arrived); nullopt when none. Throws TransportError(Disconnected).
  /// What is not a valid classic frame with an 11-bit identifier is skipped and counted.
  virtual std::optional<protocol::can::CanFrame> receive(SteadyTime deadline) = 0;
  /// Received elements or frames skipped as invalid (socketcand: corrupt or unknown text).
  virtual std::uint64_t garbage() const = 0;
};

class CanTransport final : public Transport {
 public:
  /// Opens `io` (with the reconnect policy); the controller is node `node` (1..127).
  CanTransport(std::unique_ptr<CanFrameIo> io, std::uint8_t node, const TransportOptions& options);
  ~CanTransport() override;
  CanTransport(const CanTransport&) = delete;
  CanTransport& operator=(const CanTransport&) = delete;

  std::string describe() const override;
  std::size_t max_chunk_payload() const override;
  protocol::Status read_status() override;
  protocol::Status send_command(const protocol::Command& command) override;
  protocol::Status send_chunk(const protocol::Chunk& chunk) override;
  void send_heartbeat(std::uint16_t counter) override;
  TransportCounters counters() const override;

  /// The frame mover (for tests and counters).
  CanFrameIo& io() { return *io_; }

 private:
  struct Issue;
  template <class Once>
  auto run(const std::string& what, Once&& once);
  void ensure_open();
  void dispatch(const protocol::can::CanFrame& frame);
  void drain();
  std::optional<protocol::Status> wait_status(SteadyTime deadline, std::uint64_t after_generation,
                                              const std::function<bool(const protocol::Status&)>& fits);

  std::unique_ptr<CanFrameIo> io_;
  std::uint8_t node_;
  TransportOptions options_;
  protocol::can::StatusAssembler assembler_;
  bool in_snapshot_ = false;
  std::optional<protocol::Status> latest_;
  std::uint64_t generation_ = 0;  // snapshots completed so far
  std::uint64_t returned_generation_ = 0;  // the newest snapshot a call has returned
  protocol::can::CanSegmenter* segmenter_ = nullptr;  // the transfer in progress, for flow control
  bool ever_open_ = false;
  TransportCounters counters_;
};

}  // namespace hybridctl::drivers
