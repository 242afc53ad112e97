// Every decoder that reads the network takes arbitrary input without crashing or reading
// out of bounds (run under -fsanitize=address to see the latter), and refuses it with a
// message; corrupting a valid encoding is either refused or decodes to a valid value.
// Fixed seeds: a failure reproduces.

#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

#include "protocol/can_frames.hpp"
#include "protocol/can_transfer.hpp"
#include "protocol/chunk_acceptor.hpp"
#include "protocol/modbus_map.hpp"

namespace {

using namespace hybridctl::protocol;

template <class T>
void expect_refused_with_message(const Expected<T>& e) {
  if (!e) {
    EXPECT_FALSE(e.error().message.empty());
    EXPECT_NE(e.error().code, ResultCode::None);
    EXPECT_NE(e.error().code, ResultCode::Accepted);
  }
}

TEST(ProtocolFuzz, RandomRegistersAndBytes) {
  std::mt19937 rng(1234);
  for (int i = 0; i < 20000; ++i) {
    const std::size_t n = rng() % 140;
    std::vector<std::uint16_t> regs(n);
    for (auto& r : regs) r = static_cast<std::uint16_t>(rng() % 4 == 0 ? rng() % 8 : rng());
    std::vector<std::uint8_t> bytes(2 * n + rng() % 2);
    for (auto& b : bytes) b = static_cast<std::uint8_t>(rng());
    expect_refused_with_message(modbus::decode_mailbox(regs));
    expect_refused_with_message(decode_status(regs));
    expect_refused_with_message(decode_command(regs));
    expect_refused_with_message(decode_chunk_bytes(bytes, 4075));
    expect_refused_with_message(decode_status_bytes(bytes));
    const auto v = modbus::inspect_request_pdu(bytes);
    if (v.exception) {
      EXPECT_FALSE(v.message.empty());
    }
  }
}

TEST(ProtocolFuzz, CorruptedMailboxesAreRefusedOrValid) {
  std::mt19937 rng(99);
  Chunk c;
  c.seq = 3;
  c.identity_tag = 5;
  c.first_line = 10;
  c.line_count = 4;
  c.payload = "G0 X1 Y2\nG1 Z-0.5 F200\n(comment)\nM5\n";
  const auto good = *modbus::encode_mailbox(c);
  int refused = 0;
  for (int i = 0; i < 20000; ++i) {
    auto regs = good;
    const int flips = 1 + static_cast<int>(rng() % 3);
    for (int f = 0; f < flips; ++f) regs[rng() % regs.size()] ^= static_cast<std::uint16_t>(1u << (rng() % 16));
    auto d = modbus::decode_mailbox(regs);
    if (!d) {
      ++refused;
      continue;
    }
    EXPECT_FALSE(validate_chunk(*d, modbus::kMaxChunkPayload)) << "a decoded chunk is valid";
    // Payload bits are covered by the CRC: whatever got through has the original payload.
    EXPECT_EQ(d->payload, c.payload);
  }
  EXPECT_GT(refused, 0);
}

TEST(ProtocolFuzz, RandomFramesIntoEveryCanReceiver) {
  std::mt19937 rng(7);
  const std::uint8_t node = 3;
  can::CanReassembler rx(node);
  can::CanSegmenter tx(node);
  can::CommandAssembler commands(node);
  can::StatusAssembler status(node);
  ChunkAcceptor acceptor;
  acceptor.set_program(1, 1000);
  ASSERT_FALSE(tx.begin(std::vector<std::uint8_t>(300, 0x41), 1, can::Micros{0}));
  const std::uint32_t ids[] = {can::data_id(node), can::flow_control_id(node), can::command_id(node),
                               can::status_id(node), can::heartbeat_id(node), 0x123};
  for (int i = 0; i < 50000; ++i) {
    can::CanFrame f;
    f.id = ids[rng() % 6];
    f.len = static_cast<std::uint8_t>(rng() % 16);  // beyond 8 on purpose
    for (auto& b : f.data) b = static_cast<std::uint8_t>(rng() % 3 == 0 ? (rng() % 4) << 4 : rng());
    const can::Micros now{i * 50};
    auto r = rx.on_frame(f, now);
    if (r.message) acceptor.offer_message(*r.message, ControllerState::Running);
    if (r.error) {
      EXPECT_FALSE(r.error->message.empty());
    }
    rx.poll(now);
    tx.on_flow_control(f, now);
    tx.poll(now);
    auto c = commands.on_frame(f);
    if (c.error) {
      EXPECT_FALSE(c.error->message.empty());
    }
    status.on_frame(f);
    (void)can::decode_heartbeat_frame(f, node);
    (void)can::decode_flow_control(f);
    (void)can::classify_id(f.id);
  }
  SUCCEED();
}

}  // namespace
