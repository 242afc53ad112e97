// Each way a controller can lose its program, told from a polite reboot, and the lines
// `run --resume --from-line` accepts afterwards.

#include <gtest/gtest.h>

#include "common/error.hpp"
#include "drivers/controller_loss.hpp"

namespace {

using hybridctl::drivers::check_restart_line;
using hybridctl::drivers::ControllerLoss;
using hybridctl::drivers::detect_loss;
using hybridctl::drivers::describe_loss;
using hybridctl::drivers::StreamKnowledge;
using hybridctl::protocol::AlarmCode;
using hybridctl::protocol::ControllerState;
using hybridctl::protocol::Status;

constexpr std::uint64_t kOurs = 0x1234;
const StreamKnowledge kRunning{kOurs, true, 1, 3000, 4500, 300};

Status status(std::uint16_t boot, std::uint64_t identity, ControllerState state, std::uint32_t executed, std::uint32_t accepted_chunk) {
  Status s;
  s.boot_count = boot;
  s.identity = identity;
  s.state = state;
  s.last_executed_line = executed;
  s.last_accepted_chunk = accepted_chunk;
  return s;
}

TEST(ControllerLoss, ANewBootWithoutTheProgram) {
  const auto l = detect_loss(kRunning, status(2, 0, ControllerState::Idle, 0, 0), 30000);
  ASSERT_TRUE(l);
  EXPECT_EQ(l->kind, ControllerLoss::Kind::NewBootWithoutProgram);
  EXPECT_EQ(l->executed_line, 3000u);
  EXPECT_EQ(l->accepted_line, 4500u);
}

TEST(ControllerLoss, AnotherProgram) {
  const auto l = detect_loss(kRunning, status(1, 0x9999, ControllerState::Running, 10, 2), 30000);
  ASSERT_TRUE(l);
  EXPECT_EQ(l->kind, ControllerLoss::Kind::AnotherProgram);
}

TEST(ControllerLoss, StatesThatContradictTheJournal) {
  // No program, same boot count (a new controller process starts at boot 1 again).
  auto l = detect_loss(kRunning, status(1, 0, ControllerState::Idle, 0, 0), 30000);
  ASSERT_TRUE(l);
  EXPECT_EQ(l->kind, ControllerLoss::Kind::Contradiction);
  // Executed lines going backwards, even across a boot.
  l = detect_loss(kRunning, status(2, kOurs, ControllerState::Alarm, 2000, 200), 30000);
  ASSERT_TRUE(l);
  EXPECT_NE(l->what.find("went backwards, from 3000 to 2000"), std::string::npos) << l->what;
  // Accepted chunks going backwards without a boot.
  EXPECT_TRUE(detect_loss(kRunning, status(1, kOurs, ControllerState::Running, 3000, 250), 30000));
  // A started program back to IDLE.
  EXPECT_TRUE(detect_loss(kRunning, status(1, kOurs, ControllerState::Idle, 3000, 300), 30000));
}

TEST(ControllerLoss, APoliteRebootOntoTheSafePointAndAnUnstartedProgramAreNoLoss) {
  Status reboot = status(2, kOurs, ControllerState::Alarm, 3000, 290);
  reboot.alarm = AlarmCode::ControllerRestarted;
  EXPECT_FALSE(detect_loss(kRunning, reboot, 30000));
  EXPECT_FALSE(detect_loss(kRunning, status(1, kOurs, ControllerState::Running, 3100, 310), 30000));
  const StreamKnowledge not_started{kOurs, false, 1, 0, 900, 4};
  EXPECT_FALSE(detect_loss(not_started, status(2, 0, ControllerState::Idle, 0, 0), 30000));
  EXPECT_FALSE(detect_loss(StreamKnowledge{}, status(1, 0x9999, ControllerState::Running, 10, 2), 30000));
}

TEST(ControllerLoss, TheMessageNamesTheExecutedLinesTheUncertainSpanAndTheCommand) {
  const auto l = detect_loss(kRunning, status(2, 0, ControllerState::Idle, 0, 0), 30000);
  const std::string m = describe_loss(*l, "hybridctl run --resume /jobs/a");
  EXPECT_NE(m.find("executed    lines 1..3000"), std::string::npos) << m;
  EXPECT_NE(m.find("uncertain   lines 3001..4500 (1500 lines)"), std::string::npos) << m;
  EXPECT_NE(m.find("lines 4501..30000 were never sent"), std::string::npos) << m;
  EXPECT_NE(m.find("hybridctl run --resume /jobs/a --from-line 3001"), std::string::npos) << m;
}

TEST(ControllerLoss, RestartLinesOutsideTheUncertainSpanAreRefused) {
  EXPECT_NO_THROW(check_restart_line(3001, 3000, 4500, 30000));
  EXPECT_NO_THROW(check_restart_line(4501, 3000, 4500, 30000));
  EXPECT_THROW(check_restart_line(3000, 3000, 4500, 30000), hybridctl::InputError);
  EXPECT_THROW(check_restart_line(4502, 3000, 4500, 30000), hybridctl::InputError);
  EXPECT_THROW(check_restart_line(0, 3000, 4500, 30000), hybridctl::InputError);
  EXPECT_THROW(check_restart_line(30001, 3000, 4500, 30000), hybridctl::InputError);
  try {
    check_restart_line(10, 3000, 4500, 30000);
  } catch (const hybridctl::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("runs lines 10..3000 twice; the safe point is line 3001"), std::string::npos) << e.what();
  }
}

}  // namespace
