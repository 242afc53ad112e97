// Fuzz target: the program stream on CAN (docs/protocol.md, "CAN mapping"): the
// controller's reassembler (CanReassembler) fed arbitrary data frames and a host's
// segmenter (CanSegmenter) on a loopback that may drop or repeat frames, the host's
// flow-control decoding with arbitrary flow-control frames, reassembled messages offered
// to the acceptance rule (ChunkAcceptor::offer_message), and the command, status and
// heartbeat frame decoders.
//
// Input (fuzz/byte_reader.hpp): node, receiver block size and STmin, max message (u16, 0:
// 4095), receiver and sender timeouts (10 ms units), max wait frames; then operations,
// each an opcode byte (mod 9) and its arguments:
//   0 a frame to the receiver (see read_frame), answer flag   1 the receiver's timer
//   2 time passes: u16 ms (at most 3 s)   3 the host begins a message: u16 length + bytes,
//   transfer id   4 the host sends up to N frames: count byte, then a fate byte each
//   (0xFF lost, 0xFE delivered twice)   5 a flow control frame to the sender
//   6 a command frame   7 a status frame   8 a heartbeat frame
// The clock only moves forward.
// Contract: nothing throws; every frame the reassembler answers with is a flow control
// frame that decodes; a message it completes has 1..max_message bytes; while only the
// segmenter's own frames reach it (repeats allowed, nothing lost), every message it
// completes is the one sent.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "protocol/can_frames.hpp"
#include "protocol/can_transfer.hpp"
#include "protocol/chunk_acceptor.hpp"
#include "fuzz/byte_reader.hpp"
#include "fuzz/fuzz_check.hpp"

namespace protocol = hybridctl::protocol;
namespace can = hybridctl::protocol::can;
using can::CanFrame;
using can::Micros;

namespace {

// A frame: a byte with the DLC (low 4 bits, up to 15: frames from outside may claim more
// than 8) and bit 4 set for another identifier (then u16, at most 0x800), then the data
// bytes (at most 8).
CanFrame read_frame(hybridctl::fuzz::ByteReader& in, std::uint32_t usual_id) {
  CanFrame f;
  const std::uint8_t meta = in.u8();
  f.id = meta & 0x10 ? in.u16() % 0x801u : usual_id;
  f.len = meta & 0x0F;
  const auto bytes = in.bytes(std::min<std::size_t>(f.len, 8));
  std::copy(bytes.begin(), bytes.end(), f.data);
  return f;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  hybridctl::fuzz::ByteReader in({data, size});
  const auto node = static_cast<std::uint8_t>(can::kMinNode + in.u8() % can::kMaxNode);
  can::ReassemblerSettings rx_settings;
  rx_settings.block_size = in.u8();
  rx_settings.st_min = in.u8();
  const std::uint16_t max_message_given = in.u16();
  rx_settings.max_message = max_message_given == 0 ? can::kMaxMessageBytes : max_message_given;
  rx_settings.consecutive_timeout = Micros{std::int64_t{in.u8()} * 10'000};
  can::SegmenterSettings tx_settings;
  tx_settings.flow_control_timeout = Micros{std::int64_t{in.u8()} * 10'000};
  tx_settings.max_wait_frames = in.u8() % 21;
  const std::size_t max_message = std::min(rx_settings.max_message, can::kMaxMessageBytes);

  can::CanReassembler rx(node, rx_settings);
  can::CanSegmenter tx(node, tx_settings);
  protocol::AcceptorSettings acceptor_settings;
  acceptor_settings.max_chunk_payload = can::kMaxChunkPayload;
  protocol::ChunkAcceptor acceptor(acceptor_settings);
  acceptor.set_program(0x1234'5678'9ABC'DEF0ull, 1000);
  can::CommandAssembler commands(node);
  can::StatusAssembler statuses(node);
  Micros now{0};

  std::vector<std::uint8_t> sent;  // the segmenter's message
  bool clean = false;              // only the segmenter's frames reached rx since begin(), none lost

  // rx takes a frame; its answers go back to the segmenter when `answer`.
  auto deliver = [&](const CanFrame& frame, bool answer) {
    const can::ReceiveResult r = rx.on_frame(frame, now);
    if (r.error) FUZZ_CHECK(!r.error->message.empty(), "a transfer error says what happened");
    if (r.flow_control) {
      FUZZ_CHECK(r.flow_control->id == can::flow_control_id(node), "flow control goes on the node's identifier");
      FUZZ_CHECK(can::decode_flow_control(*r.flow_control).ok(), "the reassembler's flow control decodes");
      if (answer) (void)tx.on_flow_control(*r.flow_control, now);
    }
    if (r.message) {
      FUZZ_CHECK(!r.message->empty() && r.message->size() <= max_message, "a message has 1..max_message bytes");
      if (clean) FUZZ_CHECK(*r.message == sent, "a transfer without losses delivers the message sent");
      const std::size_t before = acceptor.queue().size();
      const protocol::ChunkVerdict v = acceptor.offer_message(*r.message, protocol::ControllerState::Running);
      FUZZ_CHECK(!v.message.empty(), "a chunk verdict says why");
      FUZZ_CHECK(acceptor.queue().size() == before + (v.result == protocol::ResultCode::Accepted ? 1 : 0),
                 "exactly an accepted chunk is queued");
    }
  };

  while (!in.empty()) {
    switch (in.u8() % 9) {
      case 0:  // a frame from anyone on the data identifier (or another)
        clean = false;
        {
        const CanFrame frame = read_frame(in, can::data_id(node));
        deliver(frame, in.flag());
      }
        break;
      case 1: {  // the controller's timer
        const can::ReceiveResult r = rx.poll(now);
        FUZZ_CHECK(!r.message && !r.flow_control, "a timeout neither completes a message nor answers");
        break;
      }
      case 2:
        now += Micros{std::int64_t{in.u16() % 3001} * 1000};
        break;
      case 3: {  // the host starts a message
        const auto message = in.sized_bytes(true);
        const auto refused = tx.begin(message, in.u8(), now);
        if (!refused) {
          sent = message;
          clean = true;
        }
        break;
      }
      case 4: {  // the host sends what it may; the bus loses or repeats a frame now and then
        const int frames = 1 + in.u8() % 16;
        for (int i = 0; i < frames; ++i) {
          const auto frame = tx.poll(now);
          if (!frame) break;
          FUZZ_CHECK(frame->id == can::data_id(node) && frame->len >= 1 && frame->len <= 8,
                     "the segmenter sends data frames");
          const std::uint8_t fate = in.u8();
          if (fate == 0xFF) {  // lost
            clean = false;
            continue;
          }
          deliver(*frame, true);
          if (fate == 0xFE) deliver(*frame, true);  // delivered twice
        }
        break;
      }
      case 5: {  // flow control from anyone
        const CanFrame frame = read_frame(in, can::flow_control_id(node));
        const auto error = tx.on_flow_control(frame, now);
        if (error) FUZZ_CHECK(!error->message.empty(), "a flow control error says why");
        const auto fc = can::decode_flow_control(frame);
        if (fc) FUZZ_CHECK(can::decode_flow_control(can::encode_flow_control(*fc, node)).value() == *fc,
                           "flow control round-trips");
        break;
      }
      case 6: {  // command frames
        const CanFrame frame = read_frame(in, can::command_id(node));
        const auto r = commands.on_frame(frame);
        if (r.command) {
          can::CommandAssembler again(node);
          std::optional<protocol::Command> rebuilt;
          for (const CanFrame& f : can::encode_command_frames(*r.command, node)) rebuilt = again.on_frame(f).command;
          FUZZ_CHECK(rebuilt && *rebuilt == *r.command, "a command round-trips through its frames");
        }
        if (r.error) FUZZ_CHECK(!r.error->message.empty(), "a command frame error says why");
        break;
      }
      case 7: {  // status frames
        const CanFrame frame = read_frame(in, can::status_id(node));
        const auto r = statuses.on_frame(frame);
        if (r.status) {
          can::StatusAssembler again(node);
          std::optional<protocol::Status> rebuilt;
          for (const CanFrame& f : can::encode_status_frames(*r.status, 7, node)) rebuilt = again.on_frame(f).status;
          FUZZ_CHECK(rebuilt && *rebuilt == *r.status, "a status round-trips through its frames");
        }
        if (r.error) FUZZ_CHECK(!r.error->message.empty(), "a status frame error says why");
        break;
      }
      case 8: {  // heartbeat and identifier map
        const CanFrame frame = read_frame(in, can::heartbeat_id(node));
        (void)can::decode_heartbeat_frame(frame, node);
        if (const auto address = can::classify_id(frame.id)) {
          FUZZ_CHECK(can::valid_node(address->node), "a classified identifier names a valid node");
        }
        break;
      }
    }
  }
  return 0;
}
