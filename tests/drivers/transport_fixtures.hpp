#pragma once
// Helpers for the transport tests: a plain host loop that streams a program over any
// Transport (deliberately not drivers::stream_program, so these tests exercise the
// transports alone), waiting for a state, the simulator's run report, a socat pty pair.

#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "protocol/messages.hpp"
#include "drivers/transport.hpp"

namespace hybridctl::test {

struct StreamOutcome {
  protocol::Status final_status;  ///< the status after the last chunk (and START)
  std::uint32_t chunks = 0;       ///< distinct chunks the program took
  std::uint32_t accepted = 0;     ///< chunk writes answered ACCEPTED
  std::uint32_t duplicates = 0;   ///< chunk writes answered DUPLICATE (a resend of a write that had arrived)
  std::uint32_t other_results = 0;
};

/// SET_PROGRAM, every chunk (at most `max_payload` bytes, and what the controller advertises
/// and has free), START after the first. Every step is checked with gtest assertions
/// (call with ASSERT_NO_FATAL_FAILURE).
void stream_program(drivers::Transport& transport, const std::vector<std::string>& lines, std::size_t max_payload,
                    StreamOutcome& outcome);

/// Reads the status until `state` (or the timeout, a gtest failure); the last status read.
protocol::Status wait_for_state(drivers::Transport& transport, protocol::ControllerState state,
                                std::chrono::milliseconds timeout = std::chrono::seconds(30));

/// A G-code program for the example machine (hybrid-3axis): a few setup lines, then `moves`
/// feed moves of about 28 bytes each.
std::vector<std::string> program_of(int moves);

/// A fresh directory under the build tree for one test.
std::string scratch_dir(const std::string& name);

/// The JSON file at `path` (a gtest failure and {} when it cannot be read).
nlohmann::json read_json(const std::string& path);

}  // namespace hybridctl::test
