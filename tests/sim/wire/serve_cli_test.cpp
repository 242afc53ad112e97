// `hybridctl sim serve` as a command: what it prints, what it refuses, how it stops.

#include <gtest/gtest.h>

#include <csignal>
#include <regex>

#include "sim_process.hpp"
#include "wire_client.hpp"

namespace hybridctl::test {
namespace {

TEST(SimServeCli, PrintsOneListeningLinePerEndpointThenReady) {
  SimProcess sim({"--machine", example_machine(), "--modbus", "tcp://127.0.0.1:0", "--socketcand", "127.0.0.1:0"});
  EXPECT_TRUE(std::regex_search(sim.output(), std::regex(R"(^listening modbus-tcp 127\.0\.0\.1:\d+\nlistening socketcand 127\.0\.0\.1:\d+\nready\n)")))
      << sim.output();
  EXPECT_GT(sim.modbus_port(), 0);
  EXPECT_GT(sim.socketcand_port(), 0);
  EXPECT_NE(sim.modbus_port(), sim.socketcand_port());
  EXPECT_EQ(sim.stop(), 0) << "SIGTERM is a normal end: " << sim.errors();
  EXPECT_NE(sim.output().find("stopped (signal)"), std::string::npos) << sim.output();
}

TEST(SimServeCli, SigintStopsItToo) {
  SimProcess sim({"--machine", example_machine(), "--modbus", "127.0.0.1:0"});
  ::kill(sim.pid(), SIGINT);
  EXPECT_EQ(sim.wait(10s), 0) << sim.errors();
}

TEST(SimServeCli, RefusesNonLoopbackAddressesUnlessAllowed) {
  const PeerResult r = SimProcess::run_to_exit({"--machine", example_machine(), "--modbus", "tcp://192.0.2.7:1502"});
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("not a loopback address"), std::string::npos) << r.output;
  const PeerResult can = SimProcess::run_to_exit({"--machine", example_machine(), "--socketcand", "0.0.0.0:0"});
  EXPECT_EQ(can.exit_code, 2) << can.output;
}

TEST(SimServeCli, RefusesBadArguments) {
  const std::string m = example_machine();
  for (const std::vector<std::string>& args : std::vector<std::vector<std::string>>{
           {"--machine", m},                                                      // nothing to serve
           {"--machine", m, "--modbus", "tcp://127.0.0.1"},                       // no port
           {"--machine", m, "--modbus", "tcp://127.0.0.1:70000"},                 // port out of range
           {"--machine", m, "--modbus", "tcp://controller.local:1502"},           // not an IPv4 address
           {"--machine", m, "--modbus-rtu", "/dev/null", "--baud", "12345"},      // not a standard rate
           {"--machine", m, "--socketcand", "127.0.0.1:0", "--node", "0"},        // node out of range
           {"--machine", m, "--modbus", "127.0.0.1:0", "--as-built", "x.vdb"},    // as-built without a stock
           {"--machine", m, "--modbus", "127.0.0.1:0", "--reboot-after-lines", "5,x"},
       }) {
    const PeerResult r = SimProcess::run_to_exit(args);
    std::string joined;
    for (const auto& a : args) joined += a + " ";
    EXPECT_EQ(r.exit_code, 2) << joined << "\n" << r.output;
    EXPECT_EQ(r.output.find("listening"), std::string::npos) << joined;
  }
}

TEST(SimServeCli, APortInUseIsBadInput) {
  SimProcess first({"--machine", example_machine(), "--modbus", "tcp://127.0.0.1:0"});
  const PeerResult second = SimProcess::run_to_exit(
      {"--machine", example_machine(), "--modbus", "tcp://127.0.0.1:" + std::to_string(first.modbus_port())});
  EXPECT_EQ(second.exit_code, 3) << second.output;
  EXPECT_NE(second.output.find("cannot listen"), std::string::npos) << second.output;
  EXPECT_EQ(first.stop(), 0);
}

TEST(SimServeCli, AMissingDeviceIsBadInput) {
  const PeerResult r =
      SimProcess::run_to_exit({"--machine", example_machine(), "--modbus-rtu", "/dev/hybridctl-no-such-tty"});
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("/dev/hybridctl-no-such-tty"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace hybridctl::test
