#pragma once
// Segmented transfer of chunk messages (chunk.hpp's byte form) over classic CAN, in the
// manner of ISO 15765-2 (ISO-TP), simplified: every message starts with a first frame, the
// receiver paces the sender with flow control frames. Shared by the host's SocketCAN and
// socketcand backends and by the simulator. Pure state machines: the caller moves frames
// and supplies the clock (any monotonic microsecond count).
//
// Data frames, host -> controller on 0x200 + N (byte 0's high nibble is the frame type):
//   first frame        0x1L LL TT d0..d4   L LL: message length, 12 bits, 1..4095;
//                                          TT: transfer id (chunk seq & 0xFF); up to 5 data
//                                          bytes, len = 3 + their count
//   consecutive frame  0x2S d0..d6         S: index 1, 2, ..., 15, 0, 1, ... (4 bits); up to 7
//                                          data bytes, only the last frame may carry fewer
// Flow control, controller -> host on 0x280 + N:
//   0x3F BS ST TT                          F: 0 continue to send, 1 wait, 2 overflow/abort;
//                                          BS: consecutive frames before the next flow control
//                                          (0: all); ST: minimum separation time (ISO-TP
//                                          STmin); TT: the transfer id it answers
// A message that fits in the first frame (up to 5 bytes) needs no flow control.

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "protocol/can_frames.hpp"
#include "protocol/chunk.hpp"

namespace hybridctl::protocol::can {

using Micros = std::chrono::microseconds;

inline constexpr std::size_t kMaxMessageBytes = 4095;  ///< 12-bit length field
/// Largest chunk payload over CAN: a message minus the chunk header.
inline constexpr std::size_t kMaxChunkPayload = kMaxMessageBytes - kChunkHeaderBytes;  // 4075
inline constexpr std::size_t kFirstFrameDataBytes = 5;
inline constexpr std::size_t kConsecutiveFrameDataBytes = 7;

enum class FlowStatus : std::uint8_t { ContinueToSend = 0, Wait = 1, OverflowAbort = 2 };

struct FlowControl {
  FlowStatus status = FlowStatus::ContinueToSend;
  std::uint8_t block_size = 0;  ///< consecutive frames before the next flow control; 0: no more
  std::uint8_t st_min = 0;      ///< ISO-TP encoding: 0x00..0x7F ms, 0xF1..0xF9 100..900 us
  std::uint8_t transfer_id = 0;
  friend bool operator==(const FlowControl&, const FlowControl&) = default;
};

CanFrame encode_flow_control(const FlowControl& fc, std::uint8_t node);
/// BAD_LENGTH for fewer than 4 bytes, BAD_VALUE for another frame type or flow status.
Expected<FlowControl> decode_flow_control(const CanFrame& frame);

/// The minimum separation time an STmin byte means; reserved values mean 127 ms (ISO 15765-2).
Micros st_min_duration(std::uint8_t st_min);

/// What went wrong in a transfer.
enum class TransferErrorKind {
  Busy,            ///< begin() while a transfer is in progress
  TooLong,         ///< message over the length limit (or 0 bytes)
  WrongId,         ///< a frame with another identifier was handed in (ignored)
  Malformed,       ///< a frame that cannot be parsed (ignored, or the transfer dropped)
  Unexpected,      ///< a frame that fits no transfer in progress (ignored)
  StaleFlowControl,///< flow control for another transfer id (ignored)
  SequenceError,   ///< a consecutive frame lost or reordered: transfer dropped
  Interrupted,     ///< a new first frame replaced an unfinished transfer
  Timeout,         ///< the peer went quiet: transfer dropped
  Refused,         ///< the receiver answered overflow/abort: transfer failed
  TooManyWaits,    ///< more wait frames in a row than allowed: transfer failed
};

std::string_view to_string(TransferErrorKind kind);

struct TransferError {
  TransferErrorKind kind;
  std::string message;  ///< names the frame, transfer id, expected and found values
};

struct SegmenterSettings {
  Micros flow_control_timeout{1'000'000};  ///< ISO-TP N_Bs: longest wait for a flow control
  int max_wait_frames = 10;                ///< ISO-TP N_WFTmax: wait frames in a row allowed
};

/// Sends one message at a time as frames, honouring the receiver's flow control.
///
///   CanSegmenter tx(node);
///   tx.begin(message, transfer_id, now);
///   loop: while (auto f = tx.poll(now)) send(*f);
///         on a frame from flow_control_id(node): tx.on_flow_control(frame, now);
///         until tx.state() is Done or Failed (then tx.error() says why)
class CanSegmenter {
 public:
  enum class State { Idle, Sending, AwaitingFlowControl, Done, Failed };

  explicit CanSegmenter(std::uint8_t node, SegmenterSettings settings = {});

  /// Starts a message of 1..kMaxMessageBytes bytes. Refused (error returned, nothing changes)
  /// while a transfer is Sending or AwaitingFlowControl, or for a bad length.
  std::optional<TransferError> begin(std::span<const std::uint8_t> message, std::uint8_t transfer_id, Micros now);

  /// The next frame to send at `now`, or nullopt: nothing to send, waiting for flow control,
  /// or the separation time has not passed (see next_send_time()). Fails the transfer when
  /// the flow control timeout passed.
  std::optional<CanFrame> poll(Micros now);

  /// Takes a frame received on flow_control_id(node). Garbage, stale and unexpected frames
  /// (continue or wait in the middle of a block) are ignored: returned as an error, the
  /// transfer goes on. Overflow/abort for this transfer fails it at any point.
  std::optional<TransferError> on_flow_control(const CanFrame& frame, Micros now);

  State state() const { return state_; }
  /// Why the transfer failed (state Failed).
  const std::optional<TransferError>& error() const { return error_; }
  /// When poll() may next return a consecutive frame (Sending).
  Micros next_send_time() const { return next_send_; }
  std::uint8_t transfer_id() const { return transfer_id_; }

  // Counters since construction.
  std::uint64_t frames_sent() const { return frames_sent_; }
  std::uint64_t flow_controls_received() const { return flow_controls_; }
  std::uint64_t wait_frames_received() const { return waits_total_; }

 private:
  void fail(TransferErrorKind kind, std::string message);

  std::uint8_t node_;
  SegmenterSettings settings_;
  State state_ = State::Idle;
  std::optional<TransferError> error_;
  std::vector<std::uint8_t> message_;
  std::uint8_t transfer_id_ = 0;
  std::size_t sent_bytes_ = 0;
  bool first_sent_ = false;
  std::uint8_t next_index_ = 1;
  std::uint8_t block_size_ = 0;
  std::size_t block_sent_ = 0;
  Micros st_min_{0};
  Micros next_send_{0};
  Micros deadline_{0};
  int waits_ = 0;
  std::uint64_t frames_sent_ = 0;
  std::uint64_t flow_controls_ = 0;
  std::uint64_t waits_total_ = 0;
};

struct ReassemblerSettings {
  std::uint8_t block_size = 8;                   ///< BS sent in flow control (0: no further flow control)
  std::uint8_t st_min = 0;                       ///< STmin sent in flow control
  std::size_t max_message = kMaxMessageBytes;    ///< longer first frames get overflow/abort
  Micros consecutive_timeout{1'000'000};         ///< ISO-TP N_Cr: longest gap between frames
};

/// What one frame (or a poll) did.
struct ReceiveResult {
  std::optional<std::vector<std::uint8_t>> message;  ///< a complete message
  std::uint8_t transfer_id = 0;                       ///< of the message or the transfer concerned
  std::optional<CanFrame> flow_control;               ///< send this to the sender now
  std::optional<TransferError> error;                 ///< what was dropped or ignored, and why
  bool duplicate = false;                             ///< the frame repeated the previous consecutive frame; ignored
};

/// Rebuilds messages from data frames and answers with flow control. Detects lost and
/// reordered consecutive frames (by their 4-bit index: the transfer is dropped and the
/// sender told overflow/abort), ignores an exact repeat of the previous consecutive frame
/// (CAN can deliver a frame twice), times out a silent sender, and reports garbage without
/// ever reading past a frame.
class CanReassembler {
 public:
  explicit CanReassembler(std::uint8_t node, ReassemblerSettings settings = {});

  /// Takes a frame received on data_id(node).
  ReceiveResult on_frame(const CanFrame& frame, Micros now);
  /// Drops a transfer whose next frame is overdue.
  ReceiveResult poll(Micros now);

  bool receiving() const { return receiving_; }

  // Counters since construction.
  std::uint64_t messages() const { return messages_; }
  std::uint64_t duplicates_ignored() const { return duplicates_; }
  std::uint64_t sequence_errors() const { return sequence_errors_; }
  std::uint64_t timeouts() const { return timeouts_; }
  std::uint64_t frames_ignored() const { return ignored_; }

 private:
  ReceiveResult on_first_frame(std::span<const std::uint8_t> b, const std::string& name, Micros now);
  ReceiveResult on_consecutive_frame(std::span<const std::uint8_t> b, const std::string& name, Micros now);
  /// Counts a frame that is no part of any transfer and says why.
  ReceiveResult ignore(TransferErrorKind kind, std::string message);
  /// Hands the reassembled message over.
  ReceiveResult deliver(ReceiveResult r);
  ReceiveResult drop(ReceiveResult r, TransferErrorKind kind, std::string message, bool tell_sender);
  CanFrame flow(FlowStatus status, std::uint8_t transfer_id) const;

  std::uint8_t node_;
  ReassemblerSettings settings_;
  bool receiving_ = false;
  std::uint8_t transfer_id_ = 0;
  std::size_t total_ = 0;
  std::vector<std::uint8_t> data_;
  std::uint8_t next_index_ = 1;
  std::size_t block_count_ = 0;
  bool have_previous_ = false;
  std::vector<std::uint8_t> previous_;  // the last consecutive frame's bytes, for duplicates
  Micros deadline_{0};
  std::uint64_t messages_ = 0;
  std::uint64_t duplicates_ = 0;
  std::uint64_t sequence_errors_ = 0;
  std::uint64_t timeouts_ = 0;
  std::uint64_t ignored_ = 0;
};

/// A chunk as a CAN message (encode_chunk_bytes with the CAN payload limit).
Expected<std::vector<std::uint8_t>> encode_chunk_message(const Chunk& chunk, std::size_t max_payload = kMaxChunkPayload);
Expected<Chunk> decode_chunk_message(std::span<const std::uint8_t> message, std::size_t max_payload = kMaxChunkPayload);

/// The transfer id a chunk travels under.
constexpr std::uint8_t chunk_transfer_id(std::uint32_t seq) { return static_cast<std::uint8_t>(seq & 0xFF); }

}  // namespace hybridctl::protocol::can
