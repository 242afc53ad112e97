// The simulated controller as a CAN node (sim/wire/can_node.hpp), in process: when it puts a
// status snapshot on the bus. Besides the periodic one, a host waiting on the controller
// hears at once when the state or alarm changes and when a full buffer has room for a
// chunk again, instead of a status period later.

#include <gtest/gtest.h>

#include <chrono>

#include "config/machine_loader.hpp"
#include "protocol/can_frames.hpp"
#include "protocol/can_transfer.hpp"
#include "protocol/chunk.hpp"
#include "sim/wire/can_node.hpp"
#include "sim/controller.hpp"

namespace hybridctl::sim::wire {
namespace {

namespace can = protocol::can;
using protocol::CommandCode;
using protocol::ControllerState;
using std::chrono::milliseconds;

constexpr std::uint8_t kNode = 1;

const config::Machine& machine() {
  static const config::Machine m = config::load_machine(HYBRIDCTL_SOURCE_DIR "/examples/machines/hybrid-3axis.yaml");
  return m;
}

// A bus with one node: frames the test puts on it reach the node at once; snapshots()
// collects what the node sent.
struct Bus {
  Controller controller;
  CanNode node;
  CanMicros now{1'000'000};

  explicit Bus(ControllerOptions options)
      : controller(machine(), std::move(options)), node(controller, CanNodeOptions{kNode, milliseconds(10'000), {}}) {
    node.tick(now);  // the first periodic snapshot
    snapshots();
  }

  // The snapshots the node sent since the last call, decoded.
  std::vector<protocol::Status> snapshots() {
    std::vector<protocol::Status> out;
    can::StatusAssembler assembler(kNode);
    auto& outbox = node.outbox();
    while (!outbox.empty()) {
      const can::CanFrame f = outbox.front();
      outbox.pop_front();
      if (f.id != can::status_id(kNode)) continue;
      if (auto r = assembler.on_frame(f); r.status) out.push_back(*r.status);
    }
    return out;
  }

  void later(milliseconds dt) { now += std::chrono::duration_cast<CanMicros>(dt); }

  void command(CommandCode code, std::uint16_t seq, std::uint64_t identity = 0, std::uint32_t lines = 0) {
    for (const auto& f : can::encode_command_frames(protocol::Command{code, seq, identity, lines}, kNode))
      node.on_frame(f, now);
  }

  // One chunk message through the node, with its flow control, as a host segments it.
  void chunk(const protocol::Chunk& c) {
    auto message = can::encode_chunk_message(c);
    ASSERT_TRUE(message.ok());
    can::CanSegmenter segmenter(kNode);
    ASSERT_FALSE(segmenter.begin(message.value(), can::chunk_transfer_id(c.seq), now));
    while (segmenter.state() != can::CanSegmenter::State::Done) {
      ASSERT_NE(segmenter.state(), can::CanSegmenter::State::Failed);
      while (auto f = segmenter.poll(now)) node.on_frame(*f, now);
      for (const auto& f : node.outbox())
        if (f.id == can::flow_control_id(kNode)) segmenter.on_flow_control(f, now);
    }
  }
};

std::vector<std::string> program(int moves) {
  std::string text = "G21 G90 G17\nG54\nT1 M6\nS8000 M3\nG0 X0 Y0 Z20\n";
  for (int i = 0; i < moves; ++i) text += "G1 X" + std::to_string(10 + i % 50) + " Y20 Z20 F1200\n";
  return protocol::program_lines(text + "M5\nM2\n");
}

TEST(CanNode, SendsAStatusSnapshotWhenTheStateChanges) {
  Bus bus({});
  bus.later(milliseconds(5));
  bus.node.tick(bus.now);
  EXPECT_TRUE(bus.snapshots().empty()) << "nothing changed and the period (10 s) has not passed";

  bus.controller.emergency_stop();
  bus.later(milliseconds(1));
  bus.node.tick(bus.now);
  const auto s = bus.snapshots();
  ASSERT_EQ(s.size(), 1u) << "the alarm goes out at once, not at the next periodic snapshot";
  EXPECT_EQ(s[0].state, ControllerState::Alarm);
  EXPECT_EQ(s[0].alarm, protocol::AlarmCode::EmergencyStop);

  bus.later(milliseconds(1));
  bus.node.tick(bus.now);
  EXPECT_TRUE(bus.snapshots().empty()) << "one snapshot per change";
}

// A controller reached over CAN, executing as fast as it can, with no heartbeat watch.
ControllerOptions can_controller(std::uint32_t buffer_bytes = 16384) {
  ControllerOptions options;
  options.time_scale = 0;
  options.buffer_bytes = buffer_bytes;
  options.max_chunk_payload = static_cast<std::uint16_t>(can::kMaxChunkPayload);
  options.heartbeat_timeout_s = 0;
  return options;
}

TEST(CanNode, SendsAStatusSnapshotWhenAFullBufferHasRoomForAChunkAgain) {
  Bus bus(can_controller(6000));
  const auto lines = program(400);
  const std::uint64_t identity = protocol::program_identity(lines);
  bus.command(CommandCode::SetProgram, 1, identity, static_cast<std::uint32_t>(lines.size()));
  ASSERT_EQ(bus.snapshots().size(), 1u);

  // Two chunks fill the 6000-byte buffer past the point where a 4075-byte chunk fits.
  std::uint32_t line = 1;
  for (std::uint32_t seq = 1; seq <= 2; ++seq) {
    auto c = protocol::make_chunk(lines, line, seq, identity, 3000);
    ASSERT_TRUE(c.ok());
    ASSERT_NO_FATAL_FAILURE(bus.chunk(c.value()));
    line += c.value().line_count;
  }
  auto after_chunks = bus.snapshots();
  ASSERT_FALSE(after_chunks.empty());
  EXPECT_LT(after_chunks.back().free_buffer_bytes, after_chunks.back().max_chunk_payload) << "the host sees no room";

  bus.later(milliseconds(1));
  bus.node.tick(bus.now);
  EXPECT_TRUE(bus.snapshots().empty()) << "still full: nothing to tell";

  bus.command(CommandCode::Start, 2);
  bus.snapshots();  // the command's own snapshot (still full: nothing executed yet)
  bus.controller.advance(0.001);  // time scale 0: runs what is queued
  bus.later(milliseconds(1));
  bus.node.tick(bus.now);
  const auto s = bus.snapshots();
  ASSERT_EQ(s.size(), 1u) << "the room goes out at once";
  EXPECT_GE(s[0].free_buffer_bytes, s[0].max_chunk_payload);
  EXPECT_GT(s[0].last_executed_line, 0u);
}

TEST(CanNode, SendsAStatusSnapshotWhenTheProgramCompletes) {
  Bus bus(can_controller());
  const auto lines = program(20);
  const std::uint64_t identity = protocol::program_identity(lines);
  bus.command(CommandCode::SetProgram, 1, identity, static_cast<std::uint32_t>(lines.size()));
  auto c = protocol::make_chunk(lines, 1, 1, identity, can::kMaxChunkPayload);
  ASSERT_TRUE(c.ok());
  ASSERT_EQ(c.value().line_count, lines.size());
  ASSERT_NO_FATAL_FAILURE(bus.chunk(c.value()));
  bus.command(CommandCode::Start, 2);
  ASSERT_EQ(bus.snapshots().back().state, ControllerState::Running);

  bus.controller.advance(0.001);
  ASSERT_EQ(bus.controller.state(), ControllerState::Completed);
  bus.later(milliseconds(1));
  bus.node.tick(bus.now);
  const auto s = bus.snapshots();
  ASSERT_EQ(s.size(), 1u) << "the end of the program goes out at once";
  EXPECT_EQ(s[0].state, ControllerState::Completed);
  EXPECT_EQ(s[0].last_executed_line, lines.size());
}

}  // namespace
}  // namespace hybridctl::sim::wire
