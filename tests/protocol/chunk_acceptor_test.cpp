// The controller's acceptance rule: chunk k only after k-1, duplicates acknowledged and not
// queued, gaps, foreign programs, bad lines and full buffers refused; the reboot safe point;
// commands executed once per seq. The last test streams a program through a lossy,
// duplicating, reordering channel with a host that follows docs/protocol.md and checks that
// the controller queues every line exactly once, in order.

#include "protocol/chunk_acceptor.hpp"

#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

#include "protocol/can_transfer.hpp"

namespace {

using namespace hybridctl::protocol;

std::vector<std::string> program(int n) {
  std::vector<std::string> lines;
  for (int i = 1; i <= n; ++i) lines.push_back("N" + std::to_string(i) + " G1 X" + std::to_string(i % 97) + " F600");
  return lines;
}

struct Stream {
  std::vector<std::string> lines = program(40);
  std::uint64_t identity = program_identity(lines);
  std::size_t max_payload = 64;

  Chunk chunk(std::uint32_t first_line, std::uint32_t seq) const {
    auto c = make_chunk(lines, first_line, seq, identity, max_payload);
    EXPECT_TRUE(c) << c.error().message;
    return c.value();
  }
};

constexpr auto kIdle = ControllerState::Idle;
constexpr auto kRunning = ControllerState::Running;

TEST(ChunkAcceptor, AcceptsChunksInOrderAndAdvancesTheNextLine) {
  Stream s;
  ChunkAcceptor acc;
  acc.set_program(s.identity, 40);
  EXPECT_EQ(acc.next_line(), 1u);
  std::uint32_t line = 1;
  for (std::uint32_t seq = 1; line <= 40; ++seq) {
    const Chunk c = s.chunk(line, seq);
    const auto v = acc.offer(c, seq < 3 ? kIdle : kRunning);
    ASSERT_EQ(v.result, ResultCode::Accepted) << v.message;
    EXPECT_EQ(acc.last_accepted(), seq);
    line += c.line_count;
    EXPECT_EQ(acc.next_line(), line);
  }
  std::string queued;
  while (auto c = acc.take()) queued += c->payload;
  EXPECT_EQ(queued, program_text(s.lines));
  EXPECT_EQ(acc.free_bytes(), 16384u);
}

TEST(ChunkAcceptor, ADuplicateIsAcknowledgedButNotQueuedAgain) {
  Stream s;
  ChunkAcceptor acc;
  acc.set_program(s.identity, 40);
  const Chunk c1 = s.chunk(1, 1);
  ASSERT_EQ(acc.offer(c1, kIdle).result, ResultCode::Accepted);
  const auto free_after_one = acc.free_bytes();
  EXPECT_EQ(acc.offer(c1, kIdle).result, ResultCode::Duplicate);
  EXPECT_EQ(acc.queue().size(), 1u);
  EXPECT_EQ(acc.free_bytes(), free_after_one);
  EXPECT_EQ(acc.duplicates(), 1u);
  EXPECT_EQ(acc.refused(), 0u);
  // Still acknowledged in states that take no new chunks: the host learns it arrived.
  EXPECT_EQ(acc.offer(c1, ControllerState::Alarm).result, ResultCode::Duplicate);
}

TEST(ChunkAcceptor, AGapIsRefused) {
  Stream s;
  ChunkAcceptor acc;
  acc.set_program(s.identity, 40);
  const Chunk c1 = s.chunk(1, 1);
  const Chunk c2 = s.chunk(1 + c1.line_count, 2);
  const Chunk c3 = s.chunk(c2.first_line + c2.line_count, 3);
  ASSERT_EQ(acc.offer(c1, kIdle).result, ResultCode::Accepted);
  const auto v = acc.offer(c3, kIdle);
  EXPECT_EQ(v.result, ResultCode::Gap);
  EXPECT_NE(v.message.find("expected chunk 2"), std::string::npos) << v.message;
  EXPECT_EQ(acc.last_accepted(), 1u);
  EXPECT_EQ(acc.refused(), 1u);
  EXPECT_EQ(acc.offer(c2, kIdle).result, ResultCode::Accepted);
  EXPECT_EQ(acc.offer(c3, kIdle).result, ResultCode::Accepted);
}

TEST(ChunkAcceptor, NoProgramAndAnotherProgramAreRefused) {
  Stream s;
  ChunkAcceptor acc;
  EXPECT_EQ(acc.offer(s.chunk(1, 1), kIdle).result, ResultCode::NoProgram);
  acc.set_program(s.identity ^ 0x1, 40);
  EXPECT_EQ(acc.offer(s.chunk(1, 1), kIdle).result, ResultCode::IdentityMismatch);
  // Identity mismatch wins over duplicate: a chunk of another program is never "already there".
  acc.set_program(s.identity, 40);
  ASSERT_EQ(acc.offer(s.chunk(1, 1), kIdle).result, ResultCode::Accepted);
  Chunk foreign = s.chunk(1, 1);
  foreign.identity_tag ^= 0x100;
  EXPECT_EQ(acc.offer(foreign, kIdle).result, ResultCode::IdentityMismatch);
}

TEST(ChunkAcceptor, StatesWithoutIntakeRefuseNewChunks) {
  Stream s;
  for (auto state : {ControllerState::Alarm, ControllerState::Completed, ControllerState::Aborted}) {
    ChunkAcceptor acc;
    acc.set_program(s.identity, 40);
    EXPECT_EQ(acc.offer(s.chunk(1, 1), state).result, ResultCode::NotAccepting) << to_string(state);
    EXPECT_FALSE(accepts_chunks(state));
  }
  for (auto state : {ControllerState::Idle, ControllerState::Running, ControllerState::FeedHold,
                     ControllerState::ProgramStop, ControllerState::OptionalStop})
    EXPECT_TRUE(accepts_chunks(state)) << to_string(state);
}

TEST(ChunkAcceptor, LinesMustContinueTheProgramAndEndWithIt) {
  Stream s;
  ChunkAcceptor acc;
  acc.set_program(s.identity, 40);
  const auto v = acc.offer(s.chunk(2, 1), kIdle);
  EXPECT_EQ(v.result, ResultCode::LineMismatch);
  EXPECT_NE(v.message.find("from line 1"), std::string::npos) << v.message;
  // A program said to have 2 lines cannot take a chunk of 3.
  ChunkAcceptor shorter;
  shorter.set_program(s.identity, 2);
  EXPECT_EQ(shorter.offer(s.chunk(1, 1), kIdle).result, ResultCode::LineMismatch);
}

TEST(ChunkAcceptor, TooLongAndBufferFull) {
  Stream s;
  ChunkAcceptor small({.buffer_bytes = 70, .max_chunk_payload = 40});
  small.set_program(s.identity, 40);
  EXPECT_EQ(small.offer(s.chunk(1, 1), kIdle).result, ResultCode::TooLong);  // up to 64 bytes
  s.max_payload = 40;
  const Chunk c1 = s.chunk(1, 1);
  const Chunk c2 = s.chunk(1 + c1.line_count, 2);
  const Chunk c3 = s.chunk(c2.first_line + c2.line_count, 3);
  ASSERT_LE(c1.payload.size() + c2.payload.size(), 70u);
  ASSERT_GT(c1.payload.size() + c2.payload.size() + c3.payload.size(), 70u);
  ASSERT_EQ(small.offer(c1, kIdle).result, ResultCode::Accepted);
  ASSERT_EQ(small.offer(c2, kIdle).result, ResultCode::Accepted);
  EXPECT_EQ(small.offer(c3, kRunning).result, ResultCode::BufferFull);
  ASSERT_TRUE(small.take());  // the controller starts executing chunk 1: its bytes are free
  EXPECT_EQ(small.offer(c3, kRunning).result, ResultCode::Accepted);
}

TEST(ChunkAcceptor, DecodingFailuresAreVerdictsAndCountAsRefused) {
  Stream s;
  ChunkAcceptor acc;
  acc.set_program(s.identity, 40);
  auto regs = *modbus::encode_mailbox(s.chunk(1, 1));
  regs[9] ^= 0x8000;
  const auto v = acc.offer_mailbox(regs, kIdle);
  EXPECT_EQ(v.result, ResultCode::BadCrc);
  EXPECT_EQ(acc.last_written(), 1u) << "the seq is reported even for a refused write";
  EXPECT_EQ(acc.refused(), 1u);
  regs[9] ^= 0x8000;
  EXPECT_EQ(acc.offer_mailbox(regs, kIdle).result, ResultCode::Accepted);
  auto message = *can::encode_chunk_message(s.chunk(1 + acc.queue().back().line_count, 2));
  message.pop_back();
  EXPECT_EQ(acc.offer_message(message, kIdle).result, ResultCode::BadLength);
  EXPECT_EQ(acc.offer_mailbox({}, kIdle).result, ResultCode::BadLength);
  EXPECT_EQ(acc.last_written(), 0u);
}

TEST(ChunkAcceptor, FillsItsStatusFields) {
  Stream s;
  ChunkAcceptor acc({.buffer_bytes = 1000, .max_chunk_payload = 200});
  acc.set_program(s.identity, 40);
  const Chunk c1 = s.chunk(1, 1);
  acc.offer(c1, kIdle);
  acc.offer(c1, kIdle);
  Status st;
  acc.fill_status(st);
  EXPECT_EQ(st.chunk_result, ResultCode::Duplicate);
  EXPECT_EQ(st.last_written_chunk, 1u);
  EXPECT_EQ(st.last_accepted_chunk, 1u);
  EXPECT_EQ(st.next_line, 1u + c1.line_count);
  EXPECT_EQ(st.program_line_count, 40u);
  EXPECT_EQ(st.identity, s.identity);
  EXPECT_EQ(st.free_buffer_bytes, 1000u - c1.payload.size());
  EXPECT_EQ(st.max_chunk_payload, 200);
  EXPECT_EQ(st.duplicate_chunks, 1u);
  EXPECT_EQ(st.refused_chunks, 0u);
}

TEST(ChunkAcceptor, AfterARebootTheHostResumesRightAfterTheLastExecutedLine) {
  Stream s;
  // Before the reboot: chunks 1..3 accepted; chunks 1 and 2 and two lines of chunk 3 ran.
  ChunkAcceptor before;
  before.set_program(s.identity, 40);
  std::uint32_t line = 1;
  std::vector<Chunk> sent;
  for (std::uint32_t seq = 1; seq <= 3; ++seq) {
    sent.push_back(s.chunk(line, seq));
    ASSERT_EQ(before.offer(sent.back(), kRunning).result, ResultCode::Accepted);
    line += sent.back().line_count;
  }
  const SafePoint sp{s.identity, 40, 2, sent[2].first_line + 1};

  ChunkAcceptor after;  // a fresh controller: empty buffer, counters 0
  after.restore(sp);
  EXPECT_EQ(after.last_accepted(), 2u);
  EXPECT_EQ(after.next_line(), sent[2].first_line + 2);
  EXPECT_TRUE(after.queue().empty());
  // The old chunk 3 starts at lines that already ran: refused.
  EXPECT_EQ(after.offer(sent[2], kRunning).result, ResultCode::LineMismatch);
  // Chunk 2 (or earlier) is a duplicate.
  EXPECT_EQ(after.offer(sent[1], kRunning).result, ResultCode::Duplicate);
  // The host re-chunks from next_line with seq last_accepted + 1.
  const Chunk resumed = s.chunk(after.next_line(), after.last_accepted() + 1);
  EXPECT_EQ(after.offer(resumed, kRunning).result, ResultCode::Accepted);
  EXPECT_EQ(resumed.payload.substr(0, s.lines[sp.last_executed_line].size()), s.lines[sp.last_executed_line]);

  ChunkAcceptor none;
  none.restore(SafePoint{});
  EXPECT_FALSE(none.has_program());
  EXPECT_EQ(none.offer(s.chunk(1, 1), kIdle).result, ResultCode::NoProgram);
}

TEST(ChunkAcceptor, SetProgramStartsOver) {
  Stream s;
  ChunkAcceptor acc;
  acc.set_program(s.identity, 40);
  ASSERT_EQ(acc.offer(s.chunk(1, 1), kIdle).result, ResultCode::Accepted);
  acc.set_program(s.identity, 40);
  EXPECT_TRUE(acc.queue().empty());
  EXPECT_EQ(acc.last_accepted(), 0u);
  EXPECT_EQ(acc.offer(s.chunk(1, 1), kIdle).result, ResultCode::Accepted) << "not a duplicate any more";
}

// ------------------------------------------------------------ commands

TEST(CommandGate, ExecutesEachSeqOnce) {
  CommandGate gate;
  const Command start{CommandCode::Start, 1, 0, 0};
  const auto regs = encode_command(start);
  auto in = gate.offer(regs);
  ASSERT_EQ(in.decision, CommandGate::Decision::Execute);
  EXPECT_EQ(in.command, start);
  gate.record(ResultCode::Accepted);
  EXPECT_EQ(gate.offer(regs).decision, CommandGate::Decision::Repeated) << "a retried write";
  EXPECT_EQ(gate.offer(start).decision, CommandGate::Decision::Repeated);
  Status st;
  gate.fill_status(st);
  EXPECT_EQ(st.command_seq, 1);
  EXPECT_EQ(st.command_code, CommandCode::Start);
  EXPECT_EQ(st.command_result, ResultCode::Accepted);
  EXPECT_EQ(gate.offer(Command{CommandCode::FeedHold, 2, 0, 0}).decision, CommandGate::Decision::Execute);
  EXPECT_EQ(gate.offer(Command{CommandCode::FeedHold, 0, 0, 0}).decision, CommandGate::Decision::Repeated)
      << "seq 0 is no command";
  // The same code with a new seq is a new command.
  EXPECT_EQ(gate.offer(Command{CommandCode::Start, 3, 0, 0}).decision, CommandGate::Decision::Execute);
}

TEST(CommandGate, InvalidCommandsAreRecordedWithTheirResult) {
  CommandGate gate;
  auto regs = encode_command(Command{CommandCode::SetProgram, 7, 1, 0});
  auto in = gate.offer(regs);
  EXPECT_EQ(in.decision, CommandGate::Decision::Refused);
  EXPECT_EQ(gate.last_seq(), 7);
  EXPECT_EQ(gate.last_code(), CommandCode::SetProgram);
  EXPECT_EQ(gate.last_result(), ResultCode::BadArgument);
  EXPECT_EQ(gate.offer(regs).decision, CommandGate::Decision::Repeated);
  regs[command_reg::kCode] = 200;
  regs[command_reg::kSeq] = 8;
  gate.offer(regs);
  EXPECT_EQ(gate.last_result(), ResultCode::UnknownCommand);
  EXPECT_EQ(gate.last_code(), CommandCode::None);
}

// ------------------------------------------------------------ exactly once, end to end

/// The host of docs/protocol.md, "Streaming": after each write it reads the status; it
/// sends chunk last_accepted + 1 starting at next_line, and on a lost reply resends.
/// The channel loses writes, loses replies (the write happened), repeats old writes late
/// and reorders. The controller executes (takes) chunks now and then.
TEST(ChunkAcceptor, EveryLineIsQueuedExactlyOnceInOrderOverABadChannel) {
  const std::vector<std::string> lines = program(500);
  const std::uint64_t identity = program_identity(lines);
  for (std::uint32_t seed = 1; seed <= 20; ++seed) {
    std::mt19937 rng(seed);
    std::uniform_int_distribution<int> percent(0, 99);
    ChunkAcceptor controller({.buffer_bytes = 600, .max_chunk_payload = 222});
    controller.set_program(identity, static_cast<std::uint32_t>(lines.size()));
    std::string executed;
    std::vector<Chunk> in_flight;  // old writes the channel may deliver late
    int writes = 0;
    while (executed.size() < program_text(lines).size() && writes < 100000) {
      ++writes;
      // The host reads the status (reliably here: status reads are retried until they succeed).
      Status st;
      controller.fill_status(st);
      Chunk c;
      if (st.next_line <= lines.size()) {
        auto made = make_chunk(lines, st.next_line, st.last_accepted_chunk + 1, identity,
                               std::min<std::size_t>(st.max_chunk_payload, 100));
        ASSERT_TRUE(made) << made.error().message;
        c = made.value();
        in_flight.push_back(c);
        if (in_flight.size() > 8) in_flight.erase(in_flight.begin());
      }
      const int fate = percent(rng);
      if (fate < 15) {
        // lost write: nothing arrives
      } else if (fate < 30 && !in_flight.empty()) {
        // a stale write arrives (duplicate or reordered)
        const Chunk& old = in_flight[rng() % in_flight.size()];
        const std::uint32_t expected_seq = controller.last_accepted() + 1;
        const auto v = controller.offer(old, kRunning);
        if (v.result == ResultCode::Accepted) {
          EXPECT_EQ(old.seq, expected_seq);
        }
        else {
          EXPECT_TRUE(v.result == ResultCode::Duplicate || v.result == ResultCode::Gap ||
                      v.result == ResultCode::BufferFull) << to_string(v.result);
        }
      } else if (c.seq != 0) {
        controller.offer(c, kRunning);  // arrives; the reply may be lost, the host re-reads anyway
      }
      if (percent(rng) < 40)
        if (auto run = controller.take()) executed += run->payload;
    }
    while (auto run = controller.take()) executed += run->payload;
    EXPECT_EQ(executed, program_text(lines)) << "seed " << seed;
    EXPECT_GT(controller.duplicates() + controller.refused(), 0u) << "the channel did misbehave";
  }
}

}  // namespace
