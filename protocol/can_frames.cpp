// CAN identifiers, command, heartbeat and status frames.

#include "protocol/can_frames.hpp"

#include <algorithm>
#include <string>

#include "protocol/wire.hpp"

namespace hybridctl::protocol::can {

bool operator==(const CanFrame& a, const CanFrame& b) {
  if (a.id != b.id || a.len != b.len) return false;
  const auto ab = a.bytes();
  const auto bb = b.bytes();
  return std::equal(ab.begin(), ab.end(), bb.begin(), bb.end());
}

CanFrame make_frame(std::uint32_t id, std::span<const std::uint8_t> bytes) {
  CanFrame f;
  f.id = id;
  f.len = static_cast<std::uint8_t>(std::min<std::size_t>(bytes.size(), 8));
  std::copy_n(bytes.begin(), f.len, f.data);
  return f;
}

std::optional<CanAddress> classify_id(std::uint32_t id) {
  static constexpr std::pair<std::uint32_t, Channel> kBases[] = {
      {kCommandBase, Channel::Command},         {kStatusBase, Channel::Status},
      {kDataBase, Channel::Data},               {kFlowControlBase, Channel::FlowControl},
      {kHeartbeatBase, Channel::Heartbeat},
  };
  for (const auto& [base, channel] : kBases) {
    if (id > base && id <= base + kMaxNode) return CanAddress{channel, static_cast<std::uint8_t>(id - base)};
  }
  return std::nullopt;
}

namespace {

std::uint8_t parts_for(CommandCode code) { return code == CommandCode::SetProgram ? 3 : 1; }

std::string frame_name(const CanFrame& f) { return "CAN frame " + hex_id(f.id); }

}  // namespace

std::vector<CanFrame> encode_command_frames(const Command& command, std::uint8_t node) {
  const std::uint8_t parts = parts_for(command.code);
  const std::uint32_t args[3] = {static_cast<std::uint32_t>(command.identity >> 32),
                                 static_cast<std::uint32_t>(command.identity), command.line_count};
  std::vector<CanFrame> frames;
  for (std::uint8_t part = 0; part < parts; ++part) {
    std::vector<std::uint8_t> b;
    b.push_back(static_cast<std::uint8_t>(command.code));
    put_u16(b, command.seq);
    b.push_back(static_cast<std::uint8_t>((part << 4) | parts));
    put_u32(b, parts == 1 ? 0u : args[part]);
    frames.push_back(make_frame(command_id(node), b));
  }
  return frames;
}

CommandAssembler::Result CommandAssembler::on_frame(const CanFrame& frame) {
  Result r;
  if (frame.id != command_id(node_)) {
    r.error = ProtocolError{ResultCode::BadValue, frame_name(frame) + " is not node " + std::to_string(node_) +
                                                      "'s command identifier " + hex_id(command_id(node_))};
    return r;
  }
  if (frame.len != kCommandFrameBytes) {
    pending_ = false;
    r.error = ProtocolError{ResultCode::BadLength, frame_name(frame) + ": command frame of " +
                                                       std::to_string(frame.len) + " bytes, expected 8"};
    return r;
  }
  const auto b = frame.bytes();
  const std::uint8_t code = b[0];
  const std::uint16_t seq = get_u16(b, 1);
  const std::uint8_t part = b[3] >> 4;
  const std::uint8_t parts = b[3] & 0x0F;
  const std::uint32_t arg = get_u32(b, 4);
  const auto known = command_code_from_wire(code);
  const std::uint8_t expected_parts = known ? parts_for(*known) : 1;
  if (parts != expected_parts || part >= parts) {
    pending_ = false;
    r.error = ProtocolError{ResultCode::BadLength, frame_name(frame) + ": command " + std::to_string(code) +
                                                       " part " + std::to_string(part) + " of " +
                                                       std::to_string(parts) + ", expected " +
                                                       std::to_string(expected_parts) + " part(s)"};
    return r;
  }
  if (part == 0) {
    pending_ = true;
    code_ = code;
    seq_ = seq;
    parts_ = parts;
    next_part_ = 0;
    args_ = {};
  } else if (!pending_ || code != code_ || seq != seq_ || part != next_part_) {
    const bool had = pending_;
    pending_ = false;
    r.error = ProtocolError{ResultCode::BadLength,
                            frame_name(frame) + ": command part " + std::to_string(part) + " (seq " + std::to_string(seq) +
                                ") does not continue " +
                                (had ? "command seq " + std::to_string(seq_) + " at part " + std::to_string(next_part_)
                                     : std::string("any command")) +
                                "; the command is dropped"};
    return r;
  }
  args_[part] = arg;
  next_part_ = static_cast<std::uint8_t>(part + 1);
  if (next_part_ < parts_) return r;
  pending_ = false;
  CommandRegisters regs{};
  std::span<std::uint16_t> out(regs);
  out[command_reg::kCode] = code_;
  out[command_reg::kSeq] = seq_;
  if (parts_ == 3) {
    set_u32(out, command_reg::kIdentity, args_[0]);
    set_u32(out, command_reg::kIdentity + 2, args_[1]);
    set_u32(out, command_reg::kLineCount, args_[2]);
  }
  auto decoded = decode_command(regs);
  if (decoded) r.command = decoded.value();
  else r.error = decoded.error();
  return r;
}

CanFrame encode_heartbeat_frame(std::uint16_t counter, std::uint8_t node) {
  const std::uint8_t b[2] = {static_cast<std::uint8_t>(counter >> 8), static_cast<std::uint8_t>(counter)};
  return make_frame(heartbeat_id(node), b);
}

Expected<std::uint16_t> decode_heartbeat_frame(const CanFrame& frame, std::uint8_t node) {
  if (frame.id != heartbeat_id(node))
    return ProtocolError{ResultCode::BadValue, frame_name(frame) + " is not node " + std::to_string(node) +
                                                   "'s heartbeat identifier " + hex_id(heartbeat_id(node))};
  if (frame.len != 2)
    return ProtocolError{ResultCode::BadLength,
                         frame_name(frame) + ": heartbeat of " + std::to_string(frame.len) + " bytes, expected 2"};
  return get_u16(frame.bytes(), 0);
}

std::vector<CanFrame> encode_status_frames(const Status& status, std::uint8_t snapshot, std::uint8_t node) {
  const auto bytes = encode_status_bytes(status);
  std::vector<CanFrame> frames;
  for (std::size_t index = 0; index < kStatusFrameCount; ++index) {
    const std::size_t at = index * kStatusBytesPerFrame;
    const std::size_t n = std::min(kStatusBytesPerFrame, bytes.size() - at);
    std::vector<std::uint8_t> b{static_cast<std::uint8_t>(index), snapshot};
    b.insert(b.end(), bytes.begin() + static_cast<std::ptrdiff_t>(at),
             bytes.begin() + static_cast<std::ptrdiff_t>(at + n));
    frames.push_back(make_frame(status_id(node), b));
  }
  return frames;
}

StatusAssembler::Result StatusAssembler::on_frame(const CanFrame& frame) {
  Result r;
  if (frame.id != status_id(node_)) {
    r.error = ProtocolError{ResultCode::BadValue, frame_name(frame) + " is not node " + std::to_string(node_) +
                                                      "'s status identifier " + hex_id(status_id(node_))};
    return r;
  }
  const auto b = frame.bytes();
  if (b.size() < 2 || frame.len > 8) {
    pending_ = false;
    r.error = ProtocolError{ResultCode::BadLength, frame_name(frame) + ": status frame of " +
                                                       std::to_string(frame.len) + " bytes, expected 3..8"};
    return r;
  }
  const std::size_t index = b[0];
  const std::uint8_t snapshot = b[1];
  if (index >= kStatusFrameCount) {
    pending_ = false;
    r.error = ProtocolError{ResultCode::BadValue, frame_name(frame) + ": status frame index " +
                                                      std::to_string(index) + ", expected 0..15"};
    return r;
  }
  const std::size_t expected_len = 2 + std::min(kStatusBytesPerFrame, kStatusBytes - index * kStatusBytesPerFrame);
  if (b.size() != expected_len) {
    pending_ = false;
    r.error = ProtocolError{ResultCode::BadLength, frame_name(frame) + ": status frame " + std::to_string(index) +
                                                       " of " + std::to_string(b.size()) + " bytes, expected " +
                                                       std::to_string(expected_len)};
    return r;
  }
  if (index == 0) {
    if (pending_)
      r.error = ProtocolError{ResultCode::BadLength, "status snapshot " + std::to_string(snapshot_) +
                                                         " dropped at frame " + std::to_string(next_index_) +
                                                         ": a new snapshot began"};
    pending_ = true;
    snapshot_ = snapshot;
    next_index_ = 0;
    bytes_.clear();
  } else if (!pending_ || snapshot != snapshot_ || index != next_index_) {
    r.error = ProtocolError{ResultCode::BadLength,
                            frame_name(frame) + ": status frame " + std::to_string(index) + " of snapshot " +
                                std::to_string(snapshot) +
                                (pending_ ? ", expected frame " + std::to_string(next_index_) + " of snapshot " +
                                                std::to_string(snapshot_) + "; the snapshot is dropped"
                                          : ", but no snapshot began (frame 0 missing)")};
    pending_ = false;
    return r;
  }
  bytes_.insert(bytes_.end(), b.begin() + 2, b.end());
  next_index_ = index + 1;
  if (next_index_ < kStatusFrameCount) return r;
  pending_ = false;
  auto status = decode_status_bytes(bytes_);
  if (status) r.status = status.value();
  else r.error = status.error();
  return r;
}

}  // namespace hybridctl::protocol::can
