#include "sim/wire/can_node.hpp"

#include <algorithm>

#include "sim/controller.hpp"

namespace hybridctl::sim::wire {

namespace can = protocol::can;

CanMicros can_now() {
  return std::chrono::duration_cast<CanMicros>(std::chrono::steady_clock::now().time_since_epoch());
}

CanMicros can_frame_time(std::size_t data_bytes, std::uint32_t bitrate) {
  if (bitrate == 0) return CanMicros{0};
  const std::size_t n = std::min<std::size_t>(data_bytes, 8);
  const std::size_t stuffed = 34 + 8 * n;  // SOF .. CRC: the bits stuffing applies to
  const std::size_t bits = 47 + 8 * n + (stuffed - 1) / 4;
  // Round up to whole microseconds so a paced bus never runs faster than the model.
  return CanMicros{static_cast<std::int64_t>((bits * 1'000'000 + bitrate - 1) / bitrate)};
}

CanMicros CanBusClock::reserve(CanMicros now, std::size_t data_bytes) {
  if (bitrate_ == 0) return now;
  const CanMicros start = std::max(now, free_at_);
  free_at_ = start + can_frame_time(data_bytes, bitrate_);
  return free_at_;
}

CanNode::CanNode(protocol::ControllerPort& controller, CanNodeOptions options)
    : controller_(controller), options_(options), commands_(options.node), reassembler_(options.node, options.reassembler) {}

void CanNode::send(const can::CanFrame& frame) {
  outbox_.push_back(frame);
  ++counters_.frames_out;
}

void CanNode::send_status(CanMicros now) {
  const protocol::Status status = controller_.status();
  reported_state_ = status.state;
  reported_alarm_ = status.alarm;
  reported_full_ = status.free_buffer_bytes < status.max_chunk_payload;
  for (const can::CanFrame& f : can::encode_status_frames(status, snapshot_, options_.node)) send(f);
  ++snapshot_;
  ++counters_.status_snapshots;
  next_status_ = now + std::chrono::duration_cast<CanMicros>(options_.status_period);
}

void CanNode::on_frame(const can::CanFrame& frame, CanMicros now) {
  const auto address = can::classify_id(frame.id);
  if (!address || address->node != options_.node) {
    ++counters_.frames_ignored;
    return;
  }
  switch (address->channel) {
    case can::Channel::Command: {
      ++counters_.frames_in;
      const auto r = commands_.on_frame(frame);
      if (r.error) {
        ++counters_.command_errors;
        last_error_ = r.error->message;
      }
      if (r.command) {
        ++counters_.commands;
        controller_.write_command(*r.command);
        send_status(now);
      }
      return;
    }
    case can::Channel::Data: {
      ++counters_.frames_in;
      const can::ReceiveResult r = reassembler_.on_frame(frame, now);
      if (r.flow_control) send(*r.flow_control);
      if (r.error) {
        ++counters_.transfer_errors;
        last_error_ = r.error->message;
      }
      if (r.message) {
        ++counters_.chunks;
        controller_.write_message(std::span<const std::uint8_t>(*r.message));
        send_status(now);
      }
      return;
    }
    case can::Channel::Heartbeat: {
      ++counters_.frames_in;
      const auto counter = can::decode_heartbeat_frame(frame, options_.node);
      if (counter) {
        ++counters_.heartbeats;
        controller_.write_heartbeat(*counter);
      } else {
        ++counters_.heartbeat_errors;
        last_error_ = counter.error().message;
      }
      return;
    }
    case can::Channel::Status:
    case can::Channel::FlowControl:
      // What this node itself sends (another host echoing it, or a second controller
      // with our node id): not ours to take.
      ++counters_.frames_ignored;
      return;
  }
}

bool CanNode::refuse_transfer(const can::CanFrame& first_frame) {
  if (first_frame.id != can::data_id(options_.node) || first_frame.len < 3 || first_frame.len > 8 ||
      (first_frame.data[0] >> 4) != 1) {
    return false;
  }
  can::FlowControl fc;
  fc.status = can::FlowStatus::OverflowAbort;
  fc.transfer_id = first_frame.data[2];
  send(can::encode_flow_control(fc, options_.node));
  ++counters_.refused_transfers;
  return true;
}

void CanNode::tick(CanMicros now) {
  const can::ReceiveResult r = reassembler_.poll(now);
  if (r.flow_control) send(*r.flow_control);
  if (r.error) {
    ++counters_.transfer_errors;
    last_error_ = r.error->message;
  }
  // A state change (RUNNING -> COMPLETED, an alarm), or room for a chunk in a buffer the
  // host last saw full, goes out at once rather than at the next periodic snapshot: the
  // host is waiting for it, and it costs one snapshot per change.
  if (now >= next_status_ || controller_.state() != reported_state_ || controller_.alarm() != reported_alarm_) {
    send_status(now);
  } else if (reported_full_) {
    const protocol::Status s = controller_.status();
    if (s.free_buffer_bytes >= s.max_chunk_payload) send_status(now);
  }
}

CanMicros CanNode::next_deadline() const { return next_status_; }

}  // namespace hybridctl::sim::wire
