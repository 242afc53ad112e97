// Segmenter and reassembler state machines for chunk messages over CAN.

#include "protocol/can_transfer.hpp"

#include <algorithm>

#include "protocol/wire.hpp"

namespace hybridctl::protocol::can {
namespace {

constexpr std::uint8_t kFirstFrame = 0x1;
constexpr std::uint8_t kConsecutiveFrame = 0x2;
constexpr std::uint8_t kFlowControlFrame = 0x3;

std::string tid(std::uint8_t t) { return "transfer " + std::to_string(t); }

}  // namespace

std::string_view to_string(TransferErrorKind kind) {
  switch (kind) {
    case TransferErrorKind::Busy: return "busy";
    case TransferErrorKind::TooLong: return "too long";
    case TransferErrorKind::WrongId: return "wrong identifier";
    case TransferErrorKind::Malformed: return "malformed frame";
    case TransferErrorKind::Unexpected: return "unexpected frame";
    case TransferErrorKind::StaleFlowControl: return "stale flow control";
    case TransferErrorKind::SequenceError: return "sequence error";
    case TransferErrorKind::Interrupted: return "interrupted";
    case TransferErrorKind::Timeout: return "timeout";
    case TransferErrorKind::Refused: return "refused";
    case TransferErrorKind::TooManyWaits: return "too many waits";
  }
  return "unknown";
}

CanFrame encode_flow_control(const FlowControl& fc, std::uint8_t node) {
  const std::uint8_t b[4] = {static_cast<std::uint8_t>((kFlowControlFrame << 4) | static_cast<std::uint8_t>(fc.status)),
                             fc.block_size, fc.st_min, fc.transfer_id};
  return make_frame(flow_control_id(node), b);
}

Expected<FlowControl> decode_flow_control(const CanFrame& frame) {
  const auto b = frame.bytes();
  if (b.size() < 4)
    return ProtocolError{ResultCode::BadLength, "CAN frame " + hex_id(frame.id) + ": flow control of " +
                                                    std::to_string(frame.len) + " bytes, expected 4"};
  if ((b[0] >> 4) != kFlowControlFrame)
    return ProtocolError{ResultCode::BadValue, "CAN frame " + hex_id(frame.id) + ": frame type " +
                                                   std::to_string(b[0] >> 4) + ", expected 3 (flow control)"};
  const std::uint8_t fs = b[0] & 0x0F;
  if (fs > 2)
    return ProtocolError{ResultCode::BadValue, "CAN frame " + hex_id(frame.id) + ": flow status " + std::to_string(fs) +
                                                   ", expected 0 (continue), 1 (wait) or 2 (overflow/abort)"};
  return FlowControl{static_cast<FlowStatus>(fs), b[1], b[2], b[3]};
}

Micros st_min_duration(std::uint8_t st_min) {
  if (st_min <= 0x7F) return Micros{st_min * 1000};
  if (st_min >= 0xF1 && st_min <= 0xF9) return Micros{(st_min - 0xF0) * 100};
  return Micros{127'000};
}

// ---------------------------------------------------------------- segmenter

CanSegmenter::CanSegmenter(std::uint8_t node, SegmenterSettings settings) : node_(node), settings_(settings) {}

void CanSegmenter::fail(TransferErrorKind kind, std::string message) {
  state_ = State::Failed;
  error_ = TransferError{kind, std::move(message)};
}

std::optional<TransferError> CanSegmenter::begin(std::span<const std::uint8_t> message, std::uint8_t transfer_id,
                                                 Micros now) {
  if (state_ == State::Sending || state_ == State::AwaitingFlowControl)
    return TransferError{TransferErrorKind::Busy, tid(transfer_id) + " refused: " + tid(transfer_id_) +
                                                      " is still in progress"};
  if (message.empty() || message.size() > kMaxMessageBytes)
    return TransferError{TransferErrorKind::TooLong, tid(transfer_id) + ": message of " +
                                                         std::to_string(message.size()) + " bytes, expected 1..4095"};
  message_.assign(message.begin(), message.end());
  transfer_id_ = transfer_id;
  state_ = State::Sending;
  error_.reset();
  sent_bytes_ = 0;
  first_sent_ = false;
  next_index_ = 1;
  block_size_ = 0;
  block_sent_ = 0;
  st_min_ = Micros{0};
  next_send_ = now;
  waits_ = 0;
  return std::nullopt;
}

std::optional<CanFrame> CanSegmenter::poll(Micros now) {
  if (state_ == State::AwaitingFlowControl && now > deadline_) {
    fail(TransferErrorKind::Timeout, tid(transfer_id_) + ": no flow control within " +
                                         std::to_string(settings_.flow_control_timeout.count() / 1000) + " ms");
    return std::nullopt;
  }
  if (state_ != State::Sending) return std::nullopt;
  std::vector<std::uint8_t> b;
  if (!first_sent_) {
    const std::size_t n = std::min(kFirstFrameDataBytes, message_.size());
    b.push_back(static_cast<std::uint8_t>((kFirstFrame << 4) | ((message_.size() >> 8) & 0x0F)));
    b.push_back(static_cast<std::uint8_t>(message_.size() & 0xFF));
    b.push_back(transfer_id_);
    b.insert(b.end(), message_.begin(), message_.begin() + static_cast<std::ptrdiff_t>(n));
    first_sent_ = true;
    sent_bytes_ = n;
    if (sent_bytes_ == message_.size()) {
      state_ = State::Done;
    } else {
      state_ = State::AwaitingFlowControl;
      deadline_ = now + settings_.flow_control_timeout;
    }
  } else {
    if (now < next_send_) return std::nullopt;
    const std::size_t n = std::min(kConsecutiveFrameDataBytes, message_.size() - sent_bytes_);
    b.push_back(static_cast<std::uint8_t>((kConsecutiveFrame << 4) | next_index_));
    const auto from = message_.begin() + static_cast<std::ptrdiff_t>(sent_bytes_);
    b.insert(b.end(), from, from + static_cast<std::ptrdiff_t>(n));
    sent_bytes_ += n;
    next_index_ = static_cast<std::uint8_t>((next_index_ + 1) & 0x0F);
    next_send_ = now + st_min_;
    ++block_sent_;
    if (sent_bytes_ == message_.size()) {
      state_ = State::Done;
    } else if (block_size_ != 0 && block_sent_ == block_size_) {
      state_ = State::AwaitingFlowControl;
      deadline_ = now + settings_.flow_control_timeout;
    }
  }
  ++frames_sent_;
  return make_frame(data_id(node_), b);
}

std::optional<TransferError> CanSegmenter::on_flow_control(const CanFrame& frame, Micros now) {
  if (frame.id != flow_control_id(node_))
    return TransferError{TransferErrorKind::WrongId, "CAN frame " + hex_id(frame.id) + " is not node " +
                                                         std::to_string(node_) + "'s flow control identifier " +
                                                         hex_id(flow_control_id(node_)) + "; ignored"};
  const auto fc = decode_flow_control(frame);
  if (!fc) return TransferError{TransferErrorKind::Malformed, fc.error().message + "; ignored"};
  if (state_ != State::Sending && state_ != State::AwaitingFlowControl)
    return TransferError{TransferErrorKind::Unexpected,
                         "flow control for " + tid(fc->transfer_id) + " with no transfer in progress; ignored"};
  if (fc->transfer_id != transfer_id_)
    return TransferError{TransferErrorKind::StaleFlowControl, "flow control for " + tid(fc->transfer_id) +
                                                                  " while sending " + tid(transfer_id_) + "; ignored"};
  // Overflow/abort ends the transfer whenever it comes; continue and wait only answer a
  // block the segmenter is waiting on.
  if (state_ == State::Sending && fc->status != FlowStatus::OverflowAbort)
    return TransferError{TransferErrorKind::Unexpected,
                         "flow control for " + tid(fc->transfer_id) + " in the middle of a block; ignored"};
  ++flow_controls_;
  switch (fc->status) {
    case FlowStatus::ContinueToSend:
      state_ = State::Sending;
      block_size_ = fc->block_size;
      block_sent_ = 0;
      st_min_ = st_min_duration(fc->st_min);
      next_send_ = now;
      waits_ = 0;
      break;
    case FlowStatus::Wait:
      ++waits_total_;
      if (++waits_ > settings_.max_wait_frames) {
        fail(TransferErrorKind::TooManyWaits, tid(transfer_id_) + ": " + std::to_string(waits_) +
                                                  " wait frames in a row, at most " +
                                                  std::to_string(settings_.max_wait_frames) + " allowed");
      } else {
        deadline_ = now + settings_.flow_control_timeout;
      }
      break;
    case FlowStatus::OverflowAbort:
      fail(TransferErrorKind::Refused, tid(transfer_id_) + ": the receiver answered overflow/abort after " +
                                           std::to_string(sent_bytes_) + " of " + std::to_string(message_.size()) +
                                           " bytes");
      break;
  }
  return std::nullopt;
}

// ---------------------------------------------------------------- reassembler

CanReassembler::CanReassembler(std::uint8_t node, ReassemblerSettings settings) : node_(node), settings_(settings) {
  settings_.max_message = std::min(settings_.max_message, kMaxMessageBytes);
}

CanFrame CanReassembler::flow(FlowStatus status, std::uint8_t transfer_id) const {
  return encode_flow_control(FlowControl{status, settings_.block_size, settings_.st_min, transfer_id}, node_);
}

ReceiveResult CanReassembler::drop(ReceiveResult r, TransferErrorKind kind, std::string message, bool tell_sender) {
  r.error = TransferError{kind, std::move(message)};
  r.transfer_id = transfer_id_;
  if (tell_sender) r.flow_control = flow(FlowStatus::OverflowAbort, transfer_id_);
  receiving_ = false;
  data_.clear();
  return r;
}

ReceiveResult CanReassembler::ignore(TransferErrorKind kind, std::string message) {
  ++ignored_;
  ReceiveResult r;
  r.error = TransferError{kind, std::move(message)};
  return r;
}

ReceiveResult CanReassembler::deliver(ReceiveResult r) {
  ++messages_;
  r.message = std::move(data_);
  data_.clear();
  return r;
}

// Sorts a frame by kind: wrong identifier or length (ignored), first frame, consecutive
// frame, anything else (ignored).
ReceiveResult CanReassembler::on_frame(const CanFrame& frame, Micros now) {
  const std::string name = "CAN frame " + hex_id(frame.id);
  if (frame.id != data_id(node_))
    return ignore(TransferErrorKind::WrongId, name + " is not node " + std::to_string(node_) + "'s data identifier " +
                                                  hex_id(data_id(node_)) + "; ignored");
  const auto b = frame.bytes();
  if (b.empty() || frame.len > 8)
    return ignore(TransferErrorKind::Malformed,
                  name + ": data frame of " + std::to_string(frame.len) + " bytes, expected 1..8; ignored");
  const std::uint8_t type = b[0] >> 4;
  if (type == kFirstFrame) return on_first_frame(b, name, now);
  if (type == kConsecutiveFrame) return on_consecutive_frame(b, name, now);
  return ignore(TransferErrorKind::Malformed, name + ": frame type " + std::to_string(type) +
                                                  " on the data identifier, expected 1 (first) or 2 "
                                                  "(consecutive); ignored");
}

// A first frame begins a transfer (dropping one in progress), unless it repeats the
// current transfer's first frame; a message that fits it is delivered at once.
ReceiveResult CanReassembler::on_first_frame(std::span<const std::uint8_t> b, const std::string& name, Micros now) {
  if (b.size() < 3)
    return ignore(TransferErrorKind::Malformed,
                  name + ": first frame of " + std::to_string(b.size()) + " bytes, expected 4..8; ignored");
  const std::size_t total = (static_cast<std::size_t>(b[0] & 0x0F) << 8) | b[1];
  const std::uint8_t id = b[2];
  const std::size_t carried = std::min(kFirstFrameDataBytes, total);
  if (total == 0 || b.size() < 3 + carried)
    return ignore(TransferErrorKind::Malformed, name + ": first frame of " + tid(id) + " announces " +
                                                    std::to_string(total) + " bytes and carries " +
                                                    std::to_string(b.size() - 3) + "; ignored");
  const auto first_data = b.begin() + 3, first_data_end = b.begin() + 3 + static_cast<std::ptrdiff_t>(carried);
  ReceiveResult r;
  if (receiving_ && !have_previous_ && id == transfer_id_ && total == total_ &&
      std::equal(data_.begin(), data_.end(), first_data, first_data_end)) {
    ++duplicates_;  // the same first frame delivered twice; its flow control already went out
    r.transfer_id = id;
    r.duplicate = true;
    return r;
  }
  if (receiving_) {
    r.error = TransferError{TransferErrorKind::Interrupted, tid(transfer_id_) + " dropped after " +
                                                                std::to_string(data_.size()) + " of " +
                                                                std::to_string(total_) + " bytes: " + tid(id) +
                                                                " began"};
    receiving_ = false;
  }
  r.transfer_id = id;
  if (total > settings_.max_message) {
    r.error = TransferError{TransferErrorKind::TooLong, tid(id) + ": message of " + std::to_string(total) +
                                                            " bytes, at most " + std::to_string(settings_.max_message) +
                                                            " accepted"};
    r.flow_control = flow(FlowStatus::OverflowAbort, id);
    return r;
  }
  transfer_id_ = id;
  total_ = total;
  data_.assign(first_data, first_data_end);
  if (data_.size() == total_) return deliver(std::move(r));
  receiving_ = true;
  next_index_ = 1;
  block_count_ = 0;
  have_previous_ = false;
  deadline_ = now + settings_.consecutive_timeout;
  r.flow_control = flow(FlowStatus::ContinueToSend, id);
  return r;
}

// A consecutive frame continues the transfer in order; a repeat of the previous one is
// ignored, a gap or a short frame drops the transfer. Every block_size frames the
// sender gets a continue-to-send.
ReceiveResult CanReassembler::on_consecutive_frame(std::span<const std::uint8_t> b, const std::string& name,
                                                   Micros now) {
  const std::uint8_t index = b[0] & 0x0F;
  if (!receiving_)
    return ignore(TransferErrorKind::Unexpected, name + ": consecutive frame " + std::to_string(index) +
                                                     " with no transfer in progress; ignored");
  ReceiveResult r;
  r.transfer_id = transfer_id_;
  const std::span<const std::uint8_t> payload = b.subspan(1);
  const std::uint8_t previous_index = static_cast<std::uint8_t>((next_index_ + 15) & 0x0F);
  if (index != next_index_) {
    if (have_previous_ && index == previous_index &&
        std::equal(payload.begin(), payload.end(), previous_.begin(), previous_.end())) {
      ++duplicates_;
      r.duplicate = true;
      deadline_ = now + settings_.consecutive_timeout;
      return r;
    }
    ++sequence_errors_;
    return drop(std::move(r), TransferErrorKind::SequenceError,
                tid(transfer_id_) + ": consecutive frame " + std::to_string(index) + " where " +
                    std::to_string(next_index_) + " was expected after " + std::to_string(data_.size()) + " of " +
                    std::to_string(total_) + " bytes (a frame was lost, repeated or reordered); transfer dropped",
                true);
  }
  const std::size_t remaining = total_ - data_.size();
  const std::size_t expected = std::min(kConsecutiveFrameDataBytes, remaining);
  if (payload.size() < expected) {
    ++sequence_errors_;
    return drop(std::move(r), TransferErrorKind::Malformed,
                tid(transfer_id_) + ": consecutive frame " + std::to_string(index) + " carries " +
                    std::to_string(payload.size()) + " bytes, expected " + std::to_string(expected) +
                    "; transfer dropped",
                true);
  }
  data_.insert(data_.end(), payload.begin(), payload.begin() + static_cast<std::ptrdiff_t>(expected));
  previous_.assign(payload.begin(), payload.end());
  have_previous_ = true;
  next_index_ = static_cast<std::uint8_t>((next_index_ + 1) & 0x0F);
  deadline_ = now + settings_.consecutive_timeout;
  if (data_.size() == total_) {
    receiving_ = false;
    return deliver(std::move(r));
  }
  if (settings_.block_size != 0 && ++block_count_ == settings_.block_size) {
    block_count_ = 0;
    r.flow_control = flow(FlowStatus::ContinueToSend, transfer_id_);
  }
  return r;
}

ReceiveResult CanReassembler::poll(Micros now) {
  ReceiveResult r;
  if (receiving_ && now > deadline_) {
    ++timeouts_;
    return drop(std::move(r), TransferErrorKind::Timeout,
                tid(transfer_id_) + ": no consecutive frame within " +
                    std::to_string(settings_.consecutive_timeout.count() / 1000) + " ms after " +
                    std::to_string(data_.size()) + " of " + std::to_string(total_) + " bytes; transfer dropped",
                false);
  }
  return r;
}

Expected<std::vector<std::uint8_t>> encode_chunk_message(const Chunk& chunk, std::size_t max_payload) {
  return encode_chunk_bytes(chunk, std::min(max_payload, kMaxChunkPayload));
}

Expected<Chunk> decode_chunk_message(std::span<const std::uint8_t> message, std::size_t max_payload) {
  return decode_chunk_bytes(message, std::min(max_payload, kMaxChunkPayload));
}

}  // namespace hybridctl::protocol::can
