// CAN identifiers per node, and the single-purpose frames: commands (one or three frames),
// the host heartbeat and the status snapshot (16 frames).

#include "protocol/can_frames.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace {

using namespace hybridctl::protocol;
using namespace hybridctl::protocol::can;

TEST(CanIds, FollowTheDocumentedMap) {
  EXPECT_EQ(command_id(1), 0x101u);
  EXPECT_EQ(status_id(1), 0x181u);
  EXPECT_EQ(data_id(1), 0x201u);
  EXPECT_EQ(flow_control_id(1), 0x281u);
  EXPECT_EQ(heartbeat_id(1), 0x701u);
  EXPECT_EQ(command_id(127), 0x17Fu);
  EXPECT_EQ(heartbeat_id(127), 0x77Fu);
  EXPECT_FALSE(valid_node(0));
  EXPECT_FALSE(valid_node(128));
}

TEST(CanIds, ClassifyInvertsTheMapAndRejectsEverythingElse) {
  for (int node = kMinNode; node <= kMaxNode; ++node) {
    const auto n = static_cast<std::uint8_t>(node);
    EXPECT_EQ(classify_id(command_id(n)), (CanAddress{Channel::Command, n}));
    EXPECT_EQ(classify_id(status_id(n)), (CanAddress{Channel::Status, n}));
    EXPECT_EQ(classify_id(data_id(n)), (CanAddress{Channel::Data, n}));
    EXPECT_EQ(classify_id(flow_control_id(n)), (CanAddress{Channel::FlowControl, n}));
    EXPECT_EQ(classify_id(heartbeat_id(n)), (CanAddress{Channel::Heartbeat, n}));
  }
  for (std::uint32_t id : {0x000u, 0x080u, 0x100u, 0x180u, 0x200u, 0x300u, 0x700u, 0x7FFu, 0x800u, 0x1FFFFFFFu})
    EXPECT_FALSE(classify_id(id)) << std::hex << id;
}

TEST(CanCommands, SetProgramTakesThreeFramesOthersOne) {
  const Command set{CommandCode::SetProgram, 0x1234, 0x0102030405060708ull, 0x000A0B0C};
  const auto frames = encode_command_frames(set, 3);
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ(frames[0], make_frame(0x103, std::vector<std::uint8_t>{1, 0x12, 0x34, 0x03, 1, 2, 3, 4}));
  EXPECT_EQ(frames[1], make_frame(0x103, std::vector<std::uint8_t>{1, 0x12, 0x34, 0x13, 5, 6, 7, 8}));
  EXPECT_EQ(frames[2], make_frame(0x103, std::vector<std::uint8_t>{1, 0x12, 0x34, 0x23, 0, 0x0A, 0x0B, 0x0C}));
  const auto hold = encode_command_frames(Command{CommandCode::FeedHold, 7, 0, 0}, 3);
  ASSERT_EQ(hold.size(), 1u);
  EXPECT_EQ(hold[0], make_frame(0x103, std::vector<std::uint8_t>{3, 0, 7, 0x01, 0, 0, 0, 0}));
}

TEST(CanCommands, EveryCommandRoundTrips) {
  CommandAssembler assembler(9);
  for (std::uint16_t code = 1; code < kCommandCodeCount; ++code) {
    Command c{static_cast<CommandCode>(code), static_cast<std::uint16_t>(100 + code), 0, 0};
    if (c.code == CommandCode::SetProgram) {
      c.identity = 0xFFEEDDCCBBAA9988ull;
      c.line_count = 4'000'000;
    }
    const auto frames = encode_command_frames(c, 9);
    std::optional<Command> got;
    for (std::size_t i = 0; i < frames.size(); ++i) {
      auto r = assembler.on_frame(frames[i]);
      EXPECT_FALSE(r.error) << r.error->message;
      if (i + 1 < frames.size()) {
        EXPECT_FALSE(r.command);
      }
      got = r.command;
    }
    ASSERT_TRUE(got) << to_string(c.code);
    EXPECT_EQ(*got, c);
  }
}

TEST(CanCommands, BrokenSequencesOfPartsAreRefused) {
  const Command set{CommandCode::SetProgram, 5, 77, 10};
  const auto frames = encode_command_frames(set, 9);
  {
    CommandAssembler a(9);
    a.on_frame(frames[0]);
    auto r = a.on_frame(frames[2]);  // part 1 lost
    ASSERT_TRUE(r.error);
    EXPECT_EQ(r.error->code, ResultCode::BadLength);
    EXPECT_FALSE(r.command);
  }
  {
    CommandAssembler a(9);
    auto r = a.on_frame(frames[1]);  // no part 0
    ASSERT_TRUE(r.error);
  }
  {
    CommandAssembler a(9);
    a.on_frame(frames[0]);
    a.on_frame(frames[1]);
    auto other = encode_command_frames(Command{CommandCode::SetProgram, 6, 77, 10}, 9);
    auto r = a.on_frame(other[2]);  // last part of another seq
    ASSERT_TRUE(r.error);
    EXPECT_FALSE(r.command);
  }
  {
    CommandAssembler a(9);
    // A part 0 restarts: the retransmitted command still comes through whole.
    a.on_frame(frames[0]);
    a.on_frame(frames[0]);
    a.on_frame(frames[1]);
    auto r = a.on_frame(frames[2]);
    ASSERT_TRUE(r.command);
    EXPECT_EQ(*r.command, set);
  }
}

TEST(CanCommands, MalformedFramesAreRefusedWithTheDecoderRules) {
  CommandAssembler a(9);
  auto short_frame = encode_command_frames(Command{CommandCode::Start, 1, 0, 0}, 9)[0];
  short_frame.len = 7;
  EXPECT_EQ(a.on_frame(short_frame).error->code, ResultCode::BadLength);
  EXPECT_EQ(a.on_frame(encode_command_frames(Command{CommandCode::Start, 1, 0, 0}, 8)[0]).error->code,
            ResultCode::BadValue);
  EXPECT_EQ(a.on_frame(make_frame(command_id(9), std::vector<std::uint8_t>{42, 0, 1, 0x01, 0, 0, 0, 0})).error->code,
            ResultCode::UnknownCommand);
  EXPECT_EQ(a.on_frame(make_frame(command_id(9), std::vector<std::uint8_t>{2, 0, 0, 0x01, 0, 0, 0, 0})).error->code,
            ResultCode::BadValue) << "seq 0";
  EXPECT_EQ(a.on_frame(make_frame(command_id(9), std::vector<std::uint8_t>{2, 0, 1, 0x03, 0, 0, 0, 0})).error->code,
            ResultCode::BadLength) << "START claims 3 parts";
  const auto empty_program = encode_command_frames(Command{CommandCode::SetProgram, 4, 1, 0}, 9);
  a.on_frame(empty_program[0]);
  a.on_frame(empty_program[1]);
  EXPECT_EQ(a.on_frame(empty_program[2]).error->code, ResultCode::BadArgument);
}

TEST(CanHeartbeat, RoundTripsAndRefusesOtherLengths) {
  const CanFrame f = encode_heartbeat_frame(0xA1B2, 4);
  EXPECT_EQ(f, make_frame(0x704, std::vector<std::uint8_t>{0xA1, 0xB2}));
  EXPECT_EQ(*decode_heartbeat_frame(f, 4), 0xA1B2);
  EXPECT_EQ(decode_heartbeat_frame(f, 5).error().code, ResultCode::BadValue);
  CanFrame longer = f;
  longer.len = 3;
  EXPECT_EQ(decode_heartbeat_frame(longer, 4).error().code, ResultCode::BadLength);
}

Status sample_status() {
  Status s;
  s.state = ControllerState::Running;
  s.x_um = -5'000'000;
  s.y_um = 250'000;
  s.z_um = -1;
  s.identity = 0x1122334455667788ull;
  s.last_accepted_chunk = 42;
  s.spindle_rpm = 12000;
  s.deposition_on = true;
  return s;
}

TEST(CanStatus, SixteenFramesRoundTrip) {
  const Status s = sample_status();
  const auto frames = encode_status_frames(s, 0x5A, 2);
  ASSERT_EQ(frames.size(), 16u);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    EXPECT_EQ(frames[i].id, 0x182u);
    EXPECT_EQ(frames[i].data[0], i);
    EXPECT_EQ(frames[i].data[1], 0x5A);
    EXPECT_EQ(frames[i].len, i < 15 ? 8 : 4);
  }
  StatusAssembler assembler(2);
  std::optional<Status> got;
  for (const auto& f : frames) {
    auto r = assembler.on_frame(f);
    EXPECT_FALSE(r.error) << r.error->message;
    if (r.status) got = r.status;
  }
  ASSERT_TRUE(got);
  EXPECT_EQ(*got, s);
}

TEST(CanStatus, LostOrMixedFramesNeverYieldAStatus) {
  const auto a = encode_status_frames(sample_status(), 1, 2);
  Status other = sample_status();
  other.x_um = 7;
  const auto b = encode_status_frames(other, 2, 2);
  {
    StatusAssembler assembler(2);
    bool errored = false;
    for (std::size_t i = 0; i < a.size(); ++i) {
      if (i == 7) continue;
      auto r = assembler.on_frame(a[i]);
      EXPECT_FALSE(r.status);
      errored |= r.error.has_value();
    }
    EXPECT_TRUE(errored);
  }
  {
    StatusAssembler assembler(2);
    std::optional<Status> got;
    for (std::size_t i = 0; i < a.size(); ++i) {
      auto r = assembler.on_frame(i < 8 ? a[i] : b[i]);
      if (r.status) got = r.status;
    }
    EXPECT_FALSE(got) << "a status made of two snapshots";
  }
  {
    // A snapshot interrupted by the next one: the next one still comes through.
    StatusAssembler assembler(2);
    for (std::size_t i = 0; i < 5; ++i) assembler.on_frame(a[i]);
    std::optional<Status> got;
    bool reported = false;
    for (const auto& f : b) {
      auto r = assembler.on_frame(f);
      reported |= r.error.has_value();
      if (r.status) got = r.status;
    }
    EXPECT_TRUE(reported);
    ASSERT_TRUE(got);
    EXPECT_EQ(*got, other);
  }
}

TEST(CanStatus, GarbageFramesAreRefused) {
  StatusAssembler assembler(2);
  EXPECT_TRUE(assembler.on_frame(make_frame(status_id(2), std::vector<std::uint8_t>{16, 0, 1, 2})).error);
  EXPECT_TRUE(assembler.on_frame(make_frame(status_id(2), std::vector<std::uint8_t>{0})).error);
  EXPECT_TRUE(assembler.on_frame(make_frame(status_id(2), std::vector<std::uint8_t>{0, 0, 1})).error);
  EXPECT_TRUE(assembler.on_frame(make_frame(status_id(2), std::vector<std::uint8_t>{15, 0, 1, 2, 3, 4, 5, 6})).error);
  EXPECT_TRUE(assembler.on_frame(make_frame(status_id(3), std::vector<std::uint8_t>{0, 0, 1, 2, 3, 4, 5, 6})).error);
}

}  // namespace
