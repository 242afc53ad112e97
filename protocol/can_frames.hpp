#pragma once
// The program-stream protocol on classic CAN (11-bit identifiers, up to 8 data bytes):
// the frame type, the identifier map per node, and the single-purpose frames (commands,
// heartbeat, status snapshots). Chunks travel segmented on the data identifier
// (can_transfer.hpp). Multi-byte integers are big-endian. docs/protocol.md, "CAN mapping".
//
//   identifier   direction        content
//   0x100 + N    host -> ctrl     command frame(s)
//   0x180 + N    ctrl -> host     status snapshot frames (16 per snapshot)
//   0x200 + N    host -> ctrl     chunk segments (first / consecutive frames)
//   0x280 + N    ctrl -> host     flow control for the chunk segments
//   0x700 + N    host -> ctrl     host heartbeat
// N is the controller's node id, 1..127. The layout borrows CANopen's identifier blocks but
// is not CANopen: do not share node ids with CANopen devices on one bus.

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "protocol/codes.hpp"
#include "protocol/messages.hpp"

namespace hybridctl::protocol::can {

/// A classic CAN data frame. `len` is the DLC (0..8); bytes past it are not part of the
/// frame. Frames from outside may carry len > 8: every decoder checks it.
struct CanFrame {
  std::uint32_t id = 0;
  std::uint8_t len = 0;
  std::uint8_t data[8] = {};

  /// The data bytes (at most 8 even if len says more).
  std::span<const std::uint8_t> bytes() const { return {data, len <= 8 ? len : std::size_t{8}}; }

  /// Equal identifier, length and the first `len` data bytes.
  friend bool operator==(const CanFrame& a, const CanFrame& b);
};

/// A frame with `id` and the given bytes (at most 8; more are an error the caller made:
/// only the first 8 are kept and len says 8).
CanFrame make_frame(std::uint32_t id, std::span<const std::uint8_t> bytes);

inline constexpr std::uint32_t kCommandBase = 0x100;
inline constexpr std::uint32_t kStatusBase = 0x180;
inline constexpr std::uint32_t kDataBase = 0x200;
inline constexpr std::uint32_t kFlowControlBase = 0x280;
inline constexpr std::uint32_t kHeartbeatBase = 0x700;
inline constexpr int kMinNode = 1;
inline constexpr int kMaxNode = 127;

constexpr bool valid_node(int node) { return node >= kMinNode && node <= kMaxNode; }
constexpr std::uint32_t command_id(std::uint8_t node) { return kCommandBase + node; }
constexpr std::uint32_t status_id(std::uint8_t node) { return kStatusBase + node; }
constexpr std::uint32_t data_id(std::uint8_t node) { return kDataBase + node; }
constexpr std::uint32_t flow_control_id(std::uint8_t node) { return kFlowControlBase + node; }
constexpr std::uint32_t heartbeat_id(std::uint8_t node) { return kHeartbeatBase + node; }

enum class Channel { Command, Status, Data, FlowControl, Heartbeat };

struct CanAddress {
  Channel channel;
  std::uint8_t node;
  friend bool operator==(const CanAddress&, const CanAddress&) = default;
};

/// Which channel and node an identifier belongs to; nullopt for identifiers outside the map
/// (other traffic on the bus, node 0, identifiers above 0x7FF).
std::optional<CanAddress> classify_id(std::uint32_t id);

// ---- commands: 0x100 + N ----
// byte 0 command code, bytes 1-2 command seq, byte 3 (part << 4) | parts, bytes 4-7 argument
// word (uint32). SET_PROGRAM takes 3 parts (identity high word, identity low word, line
// count); other commands 1 part with argument 0. Always 8 bytes.

inline constexpr std::size_t kCommandFrameBytes = 8;

/// The frames of one command, parts in order.
std::vector<CanFrame> encode_command_frames(const Command& command, std::uint8_t node);

/// Collects command frames into commands. Parts of one command arrive in order on one
/// identifier; a part 0 starts a command (dropping an unfinished one), a part that does not
/// continue the pending command is an error and drops it. A complete command goes through
/// decode_command, so the Modbus and CAN paths validate alike.
class CommandAssembler {
 public:
  explicit CommandAssembler(std::uint8_t node) : node_(node) {}

  struct Result {
    std::optional<Command> command;       ///< a complete, valid command
    std::optional<ProtocolError> error;   ///< the frame (or the command it completed) was refused
  };
  Result on_frame(const CanFrame& frame);

 private:
  std::uint8_t node_;
  bool pending_ = false;
  std::uint8_t code_ = 0;
  std::uint16_t seq_ = 0;
  std::uint8_t parts_ = 0;
  std::uint8_t next_part_ = 0;
  std::array<std::uint32_t, 3> args_{};
};

// ---- heartbeat: 0x700 + N, 2 bytes: the host's counter ----

CanFrame encode_heartbeat_frame(std::uint16_t counter, std::uint8_t node);
/// The counter; BAD_LENGTH unless exactly 2 bytes, BAD_VALUE for another identifier.
Expected<std::uint16_t> decode_heartbeat_frame(const CanFrame& frame, std::uint8_t node);

// ---- status: 0x180 + N ----
// byte 0 frame index (0..15), byte 1 snapshot counter, bytes 2.. up to 6 bytes of the
// status block (encode_status_bytes) starting at byte 6 * index. 92 bytes -> 16 frames, the
// last carrying 2 bytes (len 4).

inline constexpr std::size_t kStatusBytesPerFrame = 6;
inline constexpr std::size_t kStatusFrameCount = (kStatusBytes + kStatusBytesPerFrame - 1) / kStatusBytesPerFrame;
static_assert(kStatusFrameCount == 16);

std::vector<CanFrame> encode_status_frames(const Status& status, std::uint8_t snapshot, std::uint8_t node);

/// Collects one snapshot's frames into a Status. Index 0 starts a snapshot; the others
/// must follow in order with the same snapshot counter, or the snapshot is dropped with an
/// error (a host never mixes two snapshots).
class StatusAssembler {
 public:
  explicit StatusAssembler(std::uint8_t node) : node_(node) {}

  struct Result {
    std::optional<Status> status;
    std::optional<ProtocolError> error;
  };
  Result on_frame(const CanFrame& frame);

 private:
  std::uint8_t node_;
  bool pending_ = false;
  std::uint8_t snapshot_ = 0;
  std::size_t next_index_ = 0;
  std::vector<std::uint8_t> bytes_;
};

}  // namespace hybridctl::protocol::can
