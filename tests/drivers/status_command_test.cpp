// `hybridctl status` against `hybridctl sim serve`: the block printed readably, --watch as
// one line per update when stdout is not a terminal, and the exit codes (0; 3 for a
// malformed URI; 6 when the controller cannot be reached).

#include <gtest/gtest.h>

#include <sstream>

#include "drivers/transport.hpp"
#include "sim_process.hpp"
#include "transport_fixtures.hpp"

namespace hybridctl::test {
namespace {

PeerResult status(std::vector<std::string> args) {
  std::vector<std::string> argv = {HYBRIDCTL_EXE, "status"};
  argv.insert(argv.end(), args.begin(), args.end());
  return run_peer(argv, std::chrono::seconds(30));
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TEST(StatusCommand, PrintsTheStatusBlock) {
  SimProcess sim({"--machine", example_machine(), "--modbus", "tcp://127.0.0.1:0", "--socketcand", "127.0.0.1:0",
                  "--time-scale", "0", "--heartbeat-timeout", "0"});
  const std::string modbus = "modbus-tcp://127.0.0.1:" + std::to_string(sim.modbus_port());
  {
    // Put a program there to see it in the status.
    auto t = drivers::open_transport(modbus);
    StreamOutcome out;
    ASSERT_NO_FATAL_FAILURE(stream_program(*t, program_of(30), t->max_chunk_payload(), out));
    wait_for_state(*t, protocol::ControllerState::Completed);
  }
  const auto lines = program_of(30);
  char identity[32];
  std::snprintf(identity, sizeof identity, "0x%016llx", static_cast<unsigned long long>(protocol::program_identity(lines)));
  for (const std::string& uri :
       {modbus, "socketcand://127.0.0.1:" + std::to_string(sim.socketcand_port()) + "/can0"}) {
    const PeerResult r = status({"--transport", uri});
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_TRUE(contains(r.output, "state         COMPLETED\n")) << r.output;
    EXPECT_TRUE(contains(r.output, "alarm         none\n")) << r.output;
    EXPECT_TRUE(contains(r.output, std::string("program       identity ") + identity + ", " +
                                       std::to_string(lines.size()) + " lines\n"))
        << r.output;
    EXPECT_TRUE(contains(r.output, "executed      line " + std::to_string(lines.size()) + " of " +
                                       std::to_string(lines.size()) + " (100.0 %)"))
        << r.output;
    EXPECT_TRUE(contains(r.output, "position      X ")) << r.output;
    EXPECT_TRUE(contains(r.output, "tool          T1\n")) << r.output;
    EXPECT_TRUE(contains(r.output, "last command  seq 2 START: ACCEPTED\n")) << r.output;
    EXPECT_TRUE(contains(r.output, ": protocol 1, boot 1\n")) << r.output;
  }
}

TEST(StatusCommand, ShowsAnAlarmWithWhatToDo) {
  SimProcess sim({"--machine", example_machine(), "--modbus", "tcp://127.0.0.1:0", "--time-scale", "0",
                  "--heartbeat-timeout", "0", "--alarm-at-line", "8"});
  const std::string uri = "modbus-tcp://127.0.0.1:" + std::to_string(sim.modbus_port());
  {
    auto t = drivers::open_transport(uri);
    StreamOutcome out;
    // 12 lines in one chunk; START; the emergency stop comes before line 8.
    ASSERT_NO_FATAL_FAILURE(stream_program(*t, program_of(5), t->max_chunk_payload(), out));
    ASSERT_EQ(out.chunks, 1u);
    wait_for_state(*t, protocol::ControllerState::Alarm);
  }
  const PeerResult r = status({"-t", uri});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "state         ALARM\n")) << r.output;
  EXPECT_TRUE(contains(r.output, "alarm         8 EMERGENCY_STOP")) << r.output;
  EXPECT_TRUE(contains(r.output, "What to do: Make the machine safe")) << r.output;
}

TEST(StatusCommand, WatchPrintsOneLinePerUpdateWhenNotATerminal) {
  SimProcess sim({"--machine", example_machine(), "--modbus", "tcp://127.0.0.1:0"});
  const PeerResult r = status({"-t", "modbus-tcp://127.0.0.1:" + std::to_string(sim.modbus_port()), "--watch", "0.1",
                               "--count", "3"});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::istringstream in(r.output);
  std::string line;
  int n = 0;
  while (std::getline(in, line)) {
    ++n;
    EXPECT_TRUE(contains(line, " IDLE alarm=NONE line=0/0 ")) << line;
    EXPECT_TRUE(contains(line, " boot=1")) << line;
  }
  EXPECT_EQ(n, 3) << r.output;
}

TEST(StatusCommand, ExitCodesForABadUriAndAnUnreachableController) {
  PeerResult r = status({"-t", "modbus-tcp://127.0.0.1"});
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_TRUE(contains(r.output, "missing ':PORT'")) << r.output;

  r = status({"-t", "modbus-tcp://127.0.0.1:1"});
  EXPECT_EQ(r.exit_code, 6) << r.output;
  EXPECT_TRUE(contains(r.output, "cannot reach the controller at modbus-tcp://127.0.0.1:1 (unreachable)")) << r.output;

  r = status({"-t", "socketcand://127.0.0.1:1/can0"});
  EXPECT_EQ(r.exit_code, 6) << r.output;

  r = status({"-t", "socketcan://vcan0"});
  if (r.exit_code == 6 && contains(r.output, "(unsupported)")) {
    EXPECT_TRUE(contains(r.output, "this kernel has no SocketCAN (AF_CAN)")) << r.output;
  } else {
    EXPECT_EQ(r.exit_code, 6) << "no controller on vcan0, yet: " << r.output;
  }

  r = status({"-t", "modbus-rtu:///dev/hybridctl-no-such-line?baud=115200"});
  EXPECT_EQ(r.exit_code, 6) << r.output;
  EXPECT_TRUE(contains(r.output, "No such file or directory")) << r.output;

  r = status({});
  EXPECT_EQ(r.exit_code, 2) << r.output;  // --transport is required
}

}  // namespace
}  // namespace hybridctl::test
