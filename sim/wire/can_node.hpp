#pragma once
// The simulated controller as a node on a CAN bus (docs/protocol.md, "CAN mapping";
// protocol/can_frames.hpp, can_transfer.hpp): it takes the frames a host puts on
// the bus and produces the frames the controller sends. Transport-free: the socketcand
// server (sim/wire/socketcand_server.hpp) and the SocketCAN endpoint
// (sim/wire/socketcan_endpoint.hpp) move its frames.
//
//   host -> node   0x100+N command frames   CommandAssembler -> controller.write_command
//                  0x200+N chunk segments   CanReassembler (answers flow control on 0x280+N)
//                                           -> controller.write_message
//                  0x700+N heartbeat        -> controller.write_heartbeat
//   node -> host   0x180+N status snapshot  16 frames, right after every command or chunk
//                                           the controller took, when its state or alarm
//                                           changes, when its buffer has room for a whole
//                                           chunk again after the last snapshot said it had
//                                           not, and at least every status_period
//                  0x280+N flow control
// Frames with other identifiers (other nodes, other traffic) are ignored and counted.

#include <chrono>
#include <cstdint>
#include <deque>
#include <string>
#include <vector>

#include "protocol/can_frames.hpp"
#include "protocol/can_transfer.hpp"
#include "protocol/controller_port.hpp"

namespace hybridctl::sim::wire {


using CanMicros = protocol::can::Micros;

struct CanNodeOptions {
  std::uint8_t node = 1;                                   ///< 1..127
  std::chrono::milliseconds status_period{100};            ///< a status snapshot at least this often
  protocol::can::ReassemblerSettings reassembler{};        ///< flow control block size, STmin, timeouts
};

struct CanNodeCounters {
  std::uint64_t frames_in = 0;          ///< frames taken from the bus for this node
  std::uint64_t frames_ignored = 0;     ///< frames for other identifiers
  std::uint64_t frames_out = 0;         ///< frames the node sent
  std::uint64_t commands = 0;           ///< complete commands handed to the controller
  std::uint64_t command_errors = 0;     ///< command frames refused by the assembler
  std::uint64_t heartbeats = 0;
  std::uint64_t heartbeat_errors = 0;
  std::uint64_t chunks = 0;             ///< reassembled messages handed to the controller
  std::uint64_t transfer_errors = 0;    ///< segments dropped or ignored (sequence, timeout, garbage)
  std::uint64_t refused_transfers = 0;  ///< first frames answered overflow/abort by refuse_transfer()
  std::uint64_t status_snapshots = 0;
};

class CanNode {
 public:
  CanNode(protocol::ControllerPort& controller, CanNodeOptions options = {});

  /// A frame seen on the bus at `now`.
  void on_frame(const protocol::can::CanFrame& frame, CanMicros now);
  /// Answers a chunk transfer's first frame with flow control overflow/abort instead of
  /// taking it (fault injection: the CAN counterpart of "server busy"). False when the
  /// frame is not a first frame on this node's data identifier (then nothing happened).
  bool refuse_transfer(const protocol::can::CanFrame& first_frame);
  /// Timed work: transfer timeouts, status snapshots when due, and a snapshot when the
  /// controller's state or alarm changed since the last one, or its buffer has room for a
  /// chunk again (call after it advanced).
  void tick(CanMicros now);
  /// When tick() next has work.
  CanMicros next_deadline() const;

  /// Frames to put on the bus, in order; the caller takes them.
  std::deque<protocol::can::CanFrame>& outbox() { return outbox_; }

  std::uint8_t node() const { return options_.node; }
  const CanNodeCounters& counters() const { return counters_; }
  /// The last transfer or command error, for the log.
  const std::string& last_error() const { return last_error_; }

 private:
  void send(const protocol::can::CanFrame& frame);
  void send_status(CanMicros now);

  protocol::ControllerPort& controller_;
  CanNodeOptions options_;
  protocol::can::CommandAssembler commands_;
  protocol::can::CanReassembler reassembler_;
  std::deque<protocol::can::CanFrame> outbox_;
  CanMicros next_status_{0};
  std::uint8_t snapshot_ = 0;
  // What the last snapshot reported: state, alarm, and whether the buffer had room for a
  // chunk of the largest size (a host with more to send waits for that room).
  protocol::ControllerState reported_state_{};
  protocol::AlarmCode reported_alarm_{};
  bool reported_full_ = false;
  CanNodeCounters counters_;
  std::string last_error_;
};

/// Bus time of a classic CAN data frame with an 11-bit identifier and `data_bytes` (0..8)
/// bytes at `bitrate` bit/s: 47 bits of framing (SOF, identifier, RTR, IDE, r0, DLC, CRC and
/// its delimiter, ACK slot and delimiter, EOF, 3 bits of intermission) + 8 per data byte,
/// plus the worst-case stuff bits over the 34 + 8n stuffed bits, floor((34 + 8n - 1) / 4).
/// 8 bytes: 111 + 24 = 135 bits, 135 us at 1 Mbit/s (7,407 frames/s). A conservative
/// model: real traffic stuffs fewer bits, so a real bus is at most ~20% faster.
CanMicros can_frame_time(std::size_t data_bytes, std::uint32_t bitrate);

/// One shared bus: frames occupy it one after another.
class CanBusClock {
 public:
  explicit CanBusClock(std::uint32_t bitrate) : bitrate_(bitrate) {}
  /// Reserves the bus for a frame offered at `now`; returns when its transmission ends
  /// (`now` itself when the bitrate is 0: no pacing).
  CanMicros reserve(CanMicros now, std::size_t data_bytes);
  std::uint32_t bitrate() const { return bitrate_; }

 private:
  std::uint32_t bitrate_;
  CanMicros free_at_{0};
};

/// Microseconds on the steady clock (the time base the CAN state machines are given).
CanMicros can_now();

}  // namespace hybridctl::sim::wire
