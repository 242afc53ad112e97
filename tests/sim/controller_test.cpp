// The simulated controller as the protocol specifies it (docs/protocol.md): programs
// arrive in chunks, run in order exactly once, stop where a real controller stops, and
// survive a reboot at the protocol's safe point.

#include <gtest/gtest.h>

#include "config/machine_loader.hpp"
#include "protocol/chunk.hpp"
#include "protocol/modbus_map.hpp"
#include "geometry/shapes.hpp"
#include "sim/controller.hpp"

namespace hybridctl::sim {
namespace {

using protocol::AlarmCode;
using protocol::CommandCode;
using protocol::ControllerState;
using protocol::ResultCode;

const config::Machine& machine() {
  static const config::Machine m = config::load_machine(HYBRIDCTL_SOURCE_DIR "/examples/machines/hybrid-3axis.yaml");
  return m;
}

// A host in a few lines: numbered commands and chunks from a program text.
struct Host {
  Controller& c;
  std::vector<std::string> lines;
  std::uint64_t identity = 0;
  std::uint16_t seq = 0;
  std::uint32_t next_chunk = 1, next_line = 1;

  Host(Controller& controller, const std::string& text)
      : c(controller), lines(protocol::program_lines(text)), identity(protocol::program_identity(lines)) {}

  ResultCode command(CommandCode code) {
    protocol::Command cmd{code, seq = protocol::next_command_seq(seq), 0, 0};
    if (code == CommandCode::SetProgram) {
      cmd.identity = identity;
      cmd.line_count = std::uint32_t(lines.size());
    }
    return c.write_command(protocol::encode_command(cmd));
  }
  // Sends the next chunk; returns the controller's verdict.
  ResultCode send() {
    auto chunk = protocol::make_chunk(lines, next_line, next_chunk, identity, protocol::modbus::kMaxChunkPayload);
    EXPECT_TRUE(chunk.ok());
    auto regs = protocol::modbus::encode_mailbox(chunk.value());
    EXPECT_TRUE(regs.ok());
    const ResultCode r = c.write_mailbox(regs.value()).result;
    if (r == ResultCode::Accepted) {
      ++next_chunk;
      next_line += chunk.value().line_count;
    }
    return r;
  }
  void send_all() {
    while (next_line <= lines.size()) ASSERT_EQ(send(), ResultCode::Accepted);
  }
};

std::string program(int moves) {
  std::string p = "G21 G90 G17\nG54\nT1 M6\nS8000 M3\nG0 X0 Y0 Z20\n";
  for (int i = 0; i < moves; ++i) p += "G1 X" + std::to_string(i % 50) + " Y" + std::to_string(i % 30) + " Z20 F1200\n";
  return p + "M5\nM2\n";
}

std::vector<std::uint32_t> one_to(std::size_t n) {
  std::vector<std::uint32_t> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = std::uint32_t(i + 1);
  return v;
}

TEST(Controller, RunsAProgramExactlyOnceInOrder) {
  Controller c(machine());
  Host host(c, program(100));
  EXPECT_EQ(host.command(CommandCode::SetProgram), ResultCode::Accepted);
  host.send_all();
  EXPECT_EQ(host.command(CommandCode::Start), ResultCode::Accepted);
  for (int i = 0; i < 100 && c.status().state == ControllerState::Running; ++i) {
    c.write_heartbeat(std::uint16_t(i + 1));
    c.advance(0.01);
  }
  EXPECT_EQ(c.status().state, ControllerState::Completed);
  EXPECT_EQ(c.executed_lines(), one_to(host.lines.size()));
  EXPECT_EQ(c.status().last_executed_chunk, host.next_chunk - 1);
  EXPECT_GT(c.report().virtual_time_s, 0);
}

TEST(Controller, DuplicatesAreAcknowledgedAndGapsRefusedNothingQueuedTwice) {
  Controller c(machine());
  Host host(c, program(60));
  host.command(CommandCode::SetProgram);
  ASSERT_EQ(host.send(), ResultCode::Accepted);
  // The same chunk again (a lost reply): acknowledged, not queued.
  --host.next_chunk;
  host.next_line = 1;
  EXPECT_EQ(host.send(), ResultCode::Duplicate);
  // Skipping a chunk: refused.
  host.next_chunk = 3;
  EXPECT_EQ(host.send(), ResultCode::Gap);
  EXPECT_EQ(c.status().last_accepted_chunk, 1u);
  EXPECT_EQ(c.status().duplicate_chunks, 1u);
  EXPECT_EQ(c.status().refused_chunks, 1u);
}

TEST(Controller, ARepeatedCommandWriteRunsOnce) {
  Controller c(machine());
  Host host(c, program(5));
  host.command(CommandCode::SetProgram);
  host.send_all();
  protocol::Command start{CommandCode::Start, 7, 0, 0};
  EXPECT_EQ(c.write_command(protocol::encode_command(start)), ResultCode::Accepted);
  protocol::Command hold{CommandCode::FeedHold, 8, 0, 0};
  EXPECT_EQ(c.write_command(protocol::encode_command(hold)), ResultCode::Accepted);
  EXPECT_EQ(c.status().state, ControllerState::FeedHold);
  // START again with the same seq: ignored, the machine stays held.
  c.write_command(protocol::encode_command(hold));
  EXPECT_EQ(c.status().state, ControllerState::FeedHold);
}

TEST(Controller, AMoveOutsideTheEnvelopeRaisesTheAlarmBeforeMoving) {
  Controller c(machine());
  Host host(c, "G21 G90\nG54\nG0 X0 Y0 Z10\nG0 X500\nM2\n");  // X travel ends at 400 - 200 = 200 in G54
  host.command(CommandCode::SetProgram);
  host.send_all();
  host.command(CommandCode::Start);
  c.advance(0.01);
  const protocol::Status s = c.status();
  EXPECT_EQ(s.state, ControllerState::Alarm);
  EXPECT_EQ(s.alarm, AlarmCode::EnvelopeViolation);
  EXPECT_EQ(s.alarm_line, 4u);
  EXPECT_EQ(s.last_executed_line, 3u);
  EXPECT_EQ(s.x_um, 200000);  // still at X0 of G54
}

TEST(Controller, UnknownToolsAndDepositionWithACutterAreAlarms) {
  {
    Controller c(machine());
    Host host(c, "G21\nT42 M6\nM2\n");
    host.command(CommandCode::SetProgram);
    host.send_all();
    host.command(CommandCode::Start);
    c.advance(0.01);
    EXPECT_EQ(c.status().alarm, AlarmCode::ToolNotInMagazine);
    EXPECT_EQ(c.status().alarm_line, 2u);
  }
  {
    Controller c(machine());
    Host host(c, "G21\nT1 M6\nM64 P0\nM2\n");  // the DED head's "on" code with the rougher in
    host.command(CommandCode::SetProgram);
    host.send_all();
    host.command(CommandCode::Start);
    c.advance(0.01);
    EXPECT_EQ(c.status().alarm, AlarmCode::DepositionWithoutHead);
  }
}

TEST(Controller, ARapidIntoTheStockIsAnAlarm) {
  ControllerOptions o;
  o.stock = geometry::make_box({0.5, {0, 0, 0}}, {{0, 0, 0}, {40, 40, 20}});
  Controller c(machine(), o);
  Host host(c, "G21 G90\nG54\nT1 M6\nS8000 M3\nG0 X20 Y20 Z30\nG0 Z10\nM2\n");
  host.command(CommandCode::SetProgram);
  host.send_all();
  host.command(CommandCode::Start);
  c.advance(0.01);
  EXPECT_EQ(c.status().alarm, AlarmCode::RapidIntoMaterial);
  EXPECT_EQ(c.status().alarm_line, 6u);
}

// A plate 2 mm thick, a pillar 8 mm high on it at x [0, 10], and a post at the far corner
// (so the simulated world reaches above the pillar), on the plan's 0.5 mm lattice.
geometry::Solid pillar_stock() {
  const geometry::Lattice l{0.5, {0, 0, 0}};
  geometry::Solid s = geometry::make_box(l, {{0, 0, 0}, {40, 20, 2}});
  s = geometry::unite(s, geometry::make_box(l, {{0, 0, 2}, {10, 20, 10}}));
  return geometry::unite(s, geometry::make_box(l, {{38, 18, 2}, {40, 20, 20}}));
}

// The DED head (T100) lays one track on the pillar's top at z 10 from x 2 to x `to`.
std::string track_program(double to) {
  return "G21 G90\nG54\nT100 M6\nG0 X2 Y10 Z30\nG1 Z10 F800\nM64 P0\nG1 X" + std::to_string(to) +
         " F800\nM65 P0\nG1 Z30 F800\nM2\n";
}

TEST(Controller, ABeadOverAirFallsAndTheControllerWarnsAndGoesOn) {
  ControllerOptions o;
  o.stock = pillar_stock();
  // On the pillar only: no warning.
  {
    Controller c(machine(), o);
    Host host(c, track_program(9));
    host.command(CommandCode::SetProgram);
    host.send_all();
    host.command(CommandCode::Start);
    c.advance(0.01);
    EXPECT_EQ(c.status().state, ControllerState::Completed);
    EXPECT_EQ(c.status().alarm, AlarmCode::None) << ::testing::PrintToString(c.report().alarms);
  }
  // Off its edge into the air: the bead beyond the cone falls, the warning names line 7,
  // the program runs to its end.
  Controller c(machine(), o);
  Host host(c, track_program(20));
  host.command(CommandCode::SetProgram);
  host.send_all();
  host.command(CommandCode::Start);
  c.advance(0.01);
  const protocol::Status s = c.status();
  EXPECT_EQ(s.state, ControllerState::Completed);
  EXPECT_EQ(s.alarm, AlarmCode::DepositionOverAir);
  EXPECT_EQ(s.alarm_line, 7u);
  EXPECT_EQ(s.last_executed_line, 10u);
  const ControllerReport r = c.report();
  ASSERT_EQ(r.alarms.size(), 1u);
  EXPECT_NE(r.alarms[0].find("line 7: DEPOSITION_OVER_AIR (warning)"), std::string::npos) << r.alarms[0];
  // Nothing was added beyond the pillar's edge plus the cone's reach (30 degrees: under a voxel
  // per layer, with one voxel of slack).
  const geometry::Solid added = geometry::subtract(c.as_built(), pillar_stock());
  EXPECT_GT(added.volume(), 0);
  EXPECT_LE(added.bounding_box_mm().max.x, 11.0);
}

TEST(Controller, TheNozzleTouchingMaterialIsACollisionAlarm) {
  ControllerOptions o;
  o.stock = pillar_stock();
  Controller c(machine(), o);
  // A track on the plate towards the post: the bead has room, but the 20 mm nozzle 10 mm
  // above it meets the post (18 mm high) on the way.
  Host host(c, "G21 G90\nG54\nT100 M6\nG0 X30 Y5 Z30\nG1 Z2 F800\nM64 P0\nG1 Y14 F800\nM65 P0\nM2\n");
  host.command(CommandCode::SetProgram);
  host.send_all();
  host.command(CommandCode::Start);
  c.advance(0.01);
  EXPECT_EQ(c.status().state, ControllerState::Alarm);
  EXPECT_EQ(c.status().alarm, AlarmCode::NozzleCollision);
  EXPECT_EQ(c.status().alarm_line, 7u);
  EXPECT_EQ(c.status().last_executed_line, 7u);
}

TEST(Controller, WithoutAHeartbeatTheMotionStops) {
  ControllerOptions o;
  o.time_scale = 1;
  o.heartbeat_timeout_s = 0.5;
  Controller c(machine(), o);
  Host host(c, program(400));
  host.command(CommandCode::SetProgram);
  host.send();
  host.command(CommandCode::Start);
  for (int i = 0; i < 10; ++i) c.advance(0.1);  // 1 s of silence
  EXPECT_EQ(c.status().state, ControllerState::Alarm);
  EXPECT_EQ(c.status().alarm, AlarmCode::HostHeartbeatLost);
  EXPECT_LT(c.executed_lines().size(), host.lines.size());
  // Reset: held, then resumed.
  EXPECT_EQ(host.command(CommandCode::ResetAlarm), ResultCode::Accepted);
  EXPECT_EQ(c.status().state, ControllerState::FeedHold);
  EXPECT_EQ(host.command(CommandCode::Resume), ResultCode::Accepted);
  EXPECT_EQ(c.status().state, ControllerState::Running);
}

TEST(Controller, AProgramStopWaitsForTheOperator) {
  Controller c(machine());
  Host host(c, "G21\n(turn the part over)\nM0\nG0 Z10\nM2\n");
  host.command(CommandCode::SetProgram);
  host.send_all();
  host.command(CommandCode::Start);
  c.advance(0.01);
  EXPECT_EQ(c.status().state, ControllerState::ProgramStop);
  EXPECT_EQ(c.status().last_executed_line, 3u);
  EXPECT_EQ(host.command(CommandCode::OperatorAck), ResultCode::Accepted);
  c.advance(0.01);
  EXPECT_EQ(c.status().state, ControllerState::Completed);
}

TEST(Controller, AfterARebootTheHostResumesFromTheSafePointAndNoLineRunsTwice) {
  ControllerOptions o;
  o.max_lines_per_advance = 30;
  Controller c(machine(), o);
  Host host(c, program(200));
  host.command(CommandCode::SetProgram);
  // Queue a few chunks, run some lines, reboot mid-chunk.
  for (int k = 0; k < 6; ++k) ASSERT_EQ(host.send(), ResultCode::Accepted);
  host.command(CommandCode::Start);
  c.write_heartbeat(1);
  c.advance(0.01);
  const std::size_t ran = c.executed_lines().size();
  ASSERT_GT(ran, 0u);
  c.reboot();
  protocol::Status s = c.status();
  EXPECT_EQ(s.state, ControllerState::Alarm);
  EXPECT_EQ(s.alarm, AlarmCode::ControllerRestarted);
  EXPECT_EQ(s.boot_count, 2);
  EXPECT_EQ(s.last_executed_line, ran);
  // The safe point: chunk last_executed_chunk + 1 must start at line last_executed_line + 1.
  EXPECT_EQ(s.last_accepted_chunk, s.last_executed_chunk);
  EXPECT_EQ(s.next_line, ran + 1);
  host.next_chunk = s.last_executed_chunk + 1;
  host.next_line = s.next_line;
  host.seq = 100;  // the gate forgot the old seq: any new one is fresh
  EXPECT_EQ(host.command(CommandCode::ResetAlarm), ResultCode::Accepted);
  host.send_all();
  EXPECT_EQ(host.command(CommandCode::Resume), ResultCode::Accepted);
  for (int i = 0; i < 100 && c.status().state == ControllerState::Running; ++i) {
    c.write_heartbeat(std::uint16_t(i + 2));
    c.advance(0.01);
  }
  EXPECT_EQ(c.status().state, ControllerState::Completed);
  EXPECT_EQ(c.executed_lines(), one_to(host.lines.size()));
}

TEST(Controller, AnInjectedAlarmStopsBeforeItsLine) {
  ControllerOptions o;
  o.alarm_at_line = 7;
  Controller c(machine(), o);
  Host host(c, program(20));
  host.command(CommandCode::SetProgram);
  host.send_all();
  host.command(CommandCode::Start);
  c.advance(0.01);
  EXPECT_EQ(c.status().alarm, AlarmCode::EmergencyStop);
  EXPECT_EQ(c.status().last_executed_line, 6u);
}

TEST(Controller, AbortIsAlwaysTakenAndAnAlarmStaysUntilReset) {
  Controller c(machine());
  Host host(c, program(50));
  EXPECT_EQ(host.command(CommandCode::Abort), ResultCode::Accepted);  // nothing to abort: no change
  EXPECT_EQ(c.status().state, ControllerState::Idle);
  host.command(CommandCode::SetProgram);
  host.send();
  host.command(CommandCode::Start);
  // A second program may not be set while this one runs.
  EXPECT_EQ(host.command(CommandCode::SetProgram), ResultCode::WrongState);
  c.emergency_stop();
  EXPECT_EQ(host.command(CommandCode::Abort), ResultCode::Accepted);
  EXPECT_EQ(c.status().state, ControllerState::Alarm);
  EXPECT_EQ(host.command(CommandCode::ResetAlarm), ResultCode::Accepted);
  EXPECT_EQ(c.status().state, ControllerState::Aborted);
  EXPECT_EQ(host.send(), ResultCode::NotAccepting);
}

TEST(Controller, AChunkOfAnotherProgramWhileRunningHoldsTheMachine) {
  Controller c(machine());
  Host host(c, program(50));
  host.command(CommandCode::SetProgram);
  host.send();
  host.command(CommandCode::Start);
  Host other(c, program(51));
  other.next_chunk = host.next_chunk;
  other.next_line = host.next_line;
  EXPECT_EQ(other.send(), ResultCode::IdentityMismatch);
  EXPECT_EQ(c.status().state, ControllerState::Alarm);
  EXPECT_EQ(c.status().alarm, AlarmCode::ProgramIdentityMismatch);
}

TEST(Controller, ASecondProgramRunsAfterOneThatEndedWithM2) {
  Controller c(machine());
  for (int round = 0; round < 2; ++round) {
    Host host(c, program(10 + round));
    host.seq = std::uint16_t(10 * (round + 1));
    ASSERT_EQ(host.command(CommandCode::SetProgram), ResultCode::Accepted) << round;
    host.send_all();
    ASSERT_EQ(host.command(CommandCode::Start), ResultCode::Accepted);
    c.advance(0.01);
    EXPECT_EQ(c.status().state, ControllerState::Completed) << round << " " << protocol::to_string(c.status().alarm);
  }
}

TEST(Controller, ARebootWithoutAStartedProgramIsJustIdle) {
  Controller c(machine());
  c.reboot();
  EXPECT_EQ(c.status().state, ControllerState::Idle);
  EXPECT_EQ(c.status().boot_count, 2);
}

}  // namespace
}  // namespace hybridctl::sim
