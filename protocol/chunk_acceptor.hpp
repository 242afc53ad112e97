#pragma once
// The controller's acceptance rule for chunks, in one place: the exactly-once, in-order
// delivery of the program stream (docs/protocol.md, "Acceptance rule"). A pure class the
// simulator (and any controller written in C++) owns: it holds the set program, the queue
// of accepted chunks and the buffer accounting, and answers every chunk write with the
// result code the status block reports.

#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>
#include <span>
#include <string>

#include "protocol/chunk.hpp"
#include "protocol/codes.hpp"
#include "protocol/messages.hpp"
#include "protocol/modbus_map.hpp"

namespace hybridctl::protocol {

/// States in which the controller queues chunks: IDLE, RUNNING, FEED_HOLD, PROGRAM_STOP,
/// OPTIONAL_STOP. Not ALARM, COMPLETED, ABORTED.
bool accepts_chunks(ControllerState state);

struct AcceptorSettings {
  std::uint32_t buffer_bytes = 16384;                          ///< payload bytes the queue holds
  std::uint16_t max_chunk_payload = modbus::kMaxChunkPayload;  ///< advertised in the status block
};

/// What a controller keeps across a reboot (non-volatile): the program and how far it ran.
struct SafePoint {
  std::uint64_t identity = 0;           ///< 0: no program was set
  std::uint32_t line_count = 0;
  std::uint32_t last_executed_chunk = 0;
  std::uint32_t last_executed_line = 0;
};

struct ChunkVerdict {
  ResultCode result = ResultCode::None;
  std::string message;  ///< for the log: which chunk, what was expected
};

class ChunkAcceptor {
 public:
  explicit ChunkAcceptor(AcceptorSettings settings = {});

  /// SET_PROGRAM: forgets the queue; last accepted 0; next line 1.
  void set_program(std::uint64_t identity, std::uint32_t line_count);

  /// After a reboot (on a fresh acceptor): the program of the safe point, an empty queue,
  /// last accepted = last executed chunk, next line = last executed line + 1. The host
  /// resends from chunk last_executed_chunk + 1 starting at that line.
  void restore(const SafePoint& safe_point);

  /// ABORT: drops the queued chunks (the program stays set; the state refuses new chunks).
  void discard_queue();

  /// The acceptance rule, checks in this order (the first that applies decides):
  ///   1. no program set                                   NO_PROGRAM
  ///   2. identity tag != low 32 bits of the identity      IDENTITY_MISMATCH
  ///   3. seq <= last accepted                             DUPLICATE (not queued again)
  ///   4. state takes no chunks (accepts_chunks)           NOT_ACCEPTING
  ///   5. seq > last accepted + 1                          GAP
  ///   6. first line != next line, or lines past the end   LINE_MISMATCH
  ///   7. payload > max chunk payload                      TOO_LONG
  ///   8. payload > free buffer bytes                      BUFFER_FULL
  ///   otherwise                                           ACCEPTED: queued, last accepted = seq,
  ///                                                       next line += line count
  /// `chunk` is assumed valid in itself (decoded, or validate_chunk passed); invalid chunks
  /// come through offer_mailbox / offer_message, which decode first.
  ChunkVerdict offer(const Chunk& chunk, ControllerState state);

  /// Decodes a mailbox write (modbus::decode_mailbox, with this acceptor's max payload) and
  /// offers it; a decoding error is the verdict (BAD_LENGTH, BAD_CRC, ...).
  ChunkVerdict offer_mailbox(std::span<const std::uint16_t> registers, ControllerState state);
  /// The same for a reassembled CAN message (can::decode_chunk_message).
  ChunkVerdict offer_message(std::span<const std::uint8_t> message, ControllerState state);

  /// The oldest queued chunk, removed from the queue; its bytes become free.
  std::optional<Chunk> take();
  const std::deque<Chunk>& queue() const { return queue_; }

  bool has_program() const { return has_program_; }
  std::uint64_t identity() const { return identity_; }
  std::uint32_t line_count() const { return line_count_; }
  std::uint32_t last_accepted() const { return last_accepted_; }
  std::uint32_t next_line() const { return next_line_; }
  std::uint32_t free_bytes() const { return settings_.buffer_bytes - used_bytes_; }
  std::uint16_t max_chunk_payload() const { return settings_.max_chunk_payload; }
  std::uint32_t last_written() const { return last_written_; }
  ResultCode last_result() const { return last_result_; }
  std::uint32_t duplicates() const { return duplicates_; }
  std::uint32_t refused() const { return refused_; }

  /// Writes the acceptor's fields into a status block: chunk_result, last_written_chunk,
  /// last_accepted_chunk, next_line, program_line_count, identity, free_buffer_bytes,
  /// max_chunk_payload, duplicate_chunks, refused_chunks.
  void fill_status(Status& status) const;

 private:
  ChunkVerdict record(std::uint32_t seq, ResultCode result, std::string message);

  AcceptorSettings settings_;
  bool has_program_ = false;
  std::uint64_t identity_ = 0;
  std::uint32_t line_count_ = 0;
  std::uint32_t last_accepted_ = 0;
  std::uint32_t next_line_ = 0;
  std::uint32_t used_bytes_ = 0;
  std::deque<Chunk> queue_;
  std::uint32_t last_written_ = 0;
  ResultCode last_result_ = ResultCode::None;
  std::uint32_t duplicates_ = 0;
  std::uint32_t refused_ = 0;
};

/// The controller's exactly-once rule for commands: a command write is executed only when
/// its seq is not 0 and differs from the seq of the last command processed; a repeat of
/// that write (the host retrying after a lost reply) changes nothing and the status keeps
/// the first result.
class CommandGate {
 public:
  enum class Decision {
    Execute,   ///< new and valid: execute `command`, then call record(result)
    Repeated,  ///< same seq as the last processed command (or seq 0): do nothing
    Refused,   ///< new but invalid: already recorded with `error.code` as its result
  };
  struct Intake {
    Decision decision = Decision::Repeated;
    Command command;
    ProtocolError error;
  };

  /// A command block written over Modbus (decode_command applies).
  Intake offer(std::span<const std::uint16_t> registers);
  /// A command assembled from CAN frames (already decoded).
  Intake offer(const Command& command);
  /// The result of the command last returned as Execute.
  void record(ResultCode result);

  std::uint16_t last_seq() const { return last_seq_; }
  CommandCode last_code() const { return last_code_; }
  ResultCode last_result() const { return last_result_; }

  /// Writes command_seq, command_code and command_result into a status block.
  void fill_status(Status& status) const;

 private:
  std::uint16_t last_seq_ = 0;
  CommandCode last_code_ = CommandCode::None;
  ResultCode last_result_ = ResultCode::None;
};

}  // namespace hybridctl::protocol
