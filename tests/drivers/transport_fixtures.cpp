#include "transport_fixtures.hpp"

#include "feed_moves_program.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <thread>

#include "protocol/chunk.hpp"

namespace hybridctl::test {

using protocol::CommandCode;
using protocol::ResultCode;

void stream_program(drivers::Transport& transport, const std::vector<std::string>& lines, std::size_t max_payload,
                    StreamOutcome& outcome) {
  const std::uint64_t identity = protocol::program_identity(lines);
  protocol::Status s = transport.read_status();
  std::uint16_t seq = s.command_seq;

  const protocol::Command set{CommandCode::SetProgram, seq = protocol::next_command_seq(seq), identity,
                              static_cast<std::uint32_t>(lines.size())};
  s = transport.send_command(set);
  ASSERT_EQ(s.command_seq, set.seq);
  ASSERT_EQ(s.command_result, ResultCode::Accepted) << protocol::to_string(s.command_result);
  ASSERT_EQ(s.identity, identity);
  ASSERT_EQ(s.program_line_count, lines.size());
  ASSERT_EQ(s.next_line, 1u);

  bool started = false;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (s.next_line <= lines.size()) {
    ASSERT_LT(std::chrono::steady_clock::now(), deadline) << "streaming took over 60 s; next line " << s.next_line;
    std::size_t room = std::min<std::size_t>({max_payload, s.max_chunk_payload, s.free_buffer_bytes});
    auto chunk = protocol::make_chunk(lines, s.next_line, s.last_accepted_chunk + 1, identity, room);
    if (!chunk.ok()) {
      // Not even one line fits in the free space: let the controller execute some.
      ASSERT_EQ(chunk.error().code, ResultCode::TooLong) << chunk.error().message;
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
      s = transport.read_status();
      continue;
    }
    s = transport.send_chunk(*chunk);
    ASSERT_EQ(s.last_written_chunk, chunk->seq) << "the status after chunk " << chunk->seq << " is not about it";
    if (s.chunk_result == ResultCode::Accepted) {
      ++outcome.accepted;
    } else if (s.chunk_result == ResultCode::Duplicate) {
      ++outcome.duplicates;
    } else if (s.chunk_result == ResultCode::BufferFull) {
      ++outcome.other_results;
      continue;
    } else {
      FAIL() << "chunk " << chunk->seq << ": " << protocol::to_string(s.chunk_result);
    }
    outcome.chunks = std::max(outcome.chunks, chunk->seq);
    if (!started) {
      const protocol::Command start{CommandCode::Start, seq = protocol::next_command_seq(seq), 0, 0};
      s = transport.send_command(start);
      ASSERT_EQ(s.command_seq, start.seq);
      ASSERT_EQ(s.command_result, ResultCode::Accepted) << protocol::to_string(s.command_result);
      started = true;
    }
  }
  outcome.final_status = s;
}

protocol::Status wait_for_state(drivers::Transport& transport, protocol::ControllerState state,
                                std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  protocol::Status s = transport.read_status();
  while (s.state != state && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    s = transport.read_status();
  }
  EXPECT_EQ(s.state, state) << "state " << protocol::to_string(s.state) << ", alarm " << protocol::to_string(s.alarm)
                            << " at line " << s.alarm_line;
  return s;
}

std::vector<std::string> program_of(int moves) { return hybridctl::testing::feed_moves_program(moves); }

std::string scratch_dir(const std::string& name) {
  const auto dir = std::filesystem::path(HYBRIDCTL_BINARY_DIR) / "test-scratch" / "drivers" / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

nlohmann::json read_json(const std::string& path) {
  std::ifstream in(path);
  if (!in) {
    ADD_FAILURE() << "cannot read " << path;
    return {};
  }
  try {
    return nlohmann::json::parse(in);
  } catch (const std::exception& e) {
    ADD_FAILURE() << path << ": " << e.what();
    return {};
  }
}

}  // namespace hybridctl::test
