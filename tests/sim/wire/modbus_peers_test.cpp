// `hybridctl sim serve` over Modbus, talked to by independent peers: mbpoll (TCP and RTU
// over a socat pty pair) and a pymodbus 3.0 script.

#include <gtest/gtest.h>

#include <map>
#include <regex>
#include <sstream>

#include "sim_process.hpp"
#include "wire_client.hpp"

namespace hybridctl::test {
namespace {

// mbpoll's "[REF]: \tVALUE" lines.
std::map<int, long> mbpoll_values(const std::string& output) {
  std::map<int, long> values;
  static const std::regex line(R"(\[(\d+)\]:\s+(-?\d+))");
  for (auto it = std::sregex_iterator(output.begin(), output.end(), line); it != std::sregex_iterator(); ++it) {
    values[std::stoi((*it)[1])] = std::stol((*it)[2]);
  }
  return values;
}

// The python scripts' "STEP key=value ..." lines.
std::map<std::string, std::map<std::string, long>> step_values(const std::string& output) {
  std::map<std::string, std::map<std::string, long>> steps;
  std::istringstream lines(output);
  std::string line;
  while (std::getline(lines, line)) {
    std::istringstream words(line);
    std::string step, word;
    words >> step;
    while (words >> word) {
      const auto eq = word.find('=');
      if (eq != std::string::npos) steps[step][word.substr(0, eq)] = std::stol(word.substr(eq + 1));
    }
  }
  return steps;
}

std::vector<std::string> mbpoll_tcp(const std::string& mbpoll, int port, std::vector<std::string> args) {
  std::vector<std::string> argv = {mbpoll, "-m", "tcp", "-p", std::to_string(port), "-a", "1", "-1", "-o", "2"};
  argv.insert(argv.end(), args.begin(), args.end());
  return argv;
}

TEST(ModbusPeers, MbpollReadsTheStatusBlock) {
  const std::string mbpoll = require_program("mbpoll");
  ASSERT_FALSE(mbpoll.empty());
  SimProcess sim({"--machine", example_machine(), "--modbus", "tcp://127.0.0.1:0"});
  ASSERT_GT(sim.modbus_port(), 0) << sim.output();

  // Input registers 0..45 (mbpoll's -r is 1-based): protocol version 1, state IDLE (0).
  const PeerResult r = run_peer(mbpoll_tcp(mbpoll, sim.modbus_port(), {"-t", "3", "-r", "1", "-c", "46", "127.0.0.1"}));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto v = mbpoll_values(r.output);
  ASSERT_EQ(v.size(), 46u) << r.output;
  EXPECT_EQ(v.at(1), 1) << "protocol version";
  EXPECT_EQ(v.at(2), 0) << "state IDLE";
  EXPECT_EQ(v.at(10), 2000) << "heartbeat timeout, ms";
  EXPECT_EQ(v.at(31), 222) << "max chunk payload (Modbus)";

  // The status mirror in the holding registers says the same.
  const PeerResult mirror =
      run_peer(mbpoll_tcp(mbpoll, sim.modbus_port(), {"-t", "4", "-r", "201", "-c", "2", "127.0.0.1"}));
  ASSERT_EQ(mirror.exit_code, 0) << mirror.output;
  EXPECT_EQ(mbpoll_values(mirror.output).at(201), 1);
  EXPECT_EQ(sim.stop(), 0) << sim.errors();
}

TEST(ModbusPeers, MbpollWritesTheCommandBlock) {
  const std::string mbpoll = require_program("mbpoll");
  ASSERT_FALSE(mbpoll.empty());
  SimProcess sim({"--machine", example_machine(), "--modbus", "tcp://127.0.0.1:0"});
  const int port = sim.modbus_port();

  // SET_PROGRAM (code 1), seq 7, identity 0x2A, 10 lines: holding registers 8..15.
  const PeerResult w = run_peer(
      mbpoll_tcp(mbpoll, port, {"-t", "4", "-r", "9", "127.0.0.1", "1", "7", "0", "0", "0", "42", "0", "10"}));
  ASSERT_EQ(w.exit_code, 0) << w.output;
  EXPECT_NE(w.output.find("Written 8 references"), std::string::npos) << w.output;

  const PeerResult r = run_peer(mbpoll_tcp(mbpoll, port, {"-t", "3", "-r", "1", "-c", "30", "127.0.0.1"}));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto v = mbpoll_values(r.output);
  EXPECT_EQ(v.at(5), 1) << "command result ACCEPTED";
  EXPECT_EQ(v.at(6), 7) << "command seq";
  EXPECT_EQ(v.at(7), 1) << "command code SET_PROGRAM";
  EXPECT_EQ(v.at(21) * 65536 + v.at(22), 1) << "next line";
  EXPECT_EQ(v.at(23) * 65536 + v.at(24), 10) << "program line count";
  EXPECT_EQ(v.at(28), 42) << "identity, low word";

  // A write into the reserved registers is refused with exception 02.
  const PeerResult bad = run_peer(mbpoll_tcp(mbpoll, port, {"-t", "4", "-r", "3", "127.0.0.1", "5"}));
  EXPECT_NE(bad.exit_code, 0) << bad.output;
  EXPECT_NE(bad.output.find("Illegal data address"), std::string::npos) << bad.output;
  EXPECT_EQ(sim.stop(), 0) << sim.errors();
}

TEST(ModbusPeers, PymodbusWritesChunksWithFc23AndReadsTheResults) {
  const std::string python = require_program("/usr/bin/python3");
  ASSERT_FALSE(python.empty());
  const PeerResult has_pymodbus = run_peer({python, "-c", "import pymodbus.client"});
  ASSERT_EQ(has_pymodbus.exit_code, 0) << "pymodbus is missing (run scripts/setup): " << has_pymodbus.output;

  SimProcess sim({"--machine", example_machine(), "--modbus", "tcp://127.0.0.1:0"});
  const PeerResult r = run_peer({python, std::string(HYBRIDCTL_SOURCE_DIR) + "/tests/sim/peers/pymodbus_chunks.py",
                                 "127.0.0.1", std::to_string(sim.modbus_port())});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  auto s = step_values(r.output);
  ASSERT_EQ(s.count("gap"), 1u) << r.output;

  EXPECT_EQ(s["status"]["version"], 1);
  EXPECT_EQ(s["status"]["state"], 0);
  EXPECT_EQ(s["set_program"]["command_result"], 1) << "ACCEPTED";
  EXPECT_EQ(s["set_program"]["program_lines"], 6);
  // FC23 returns the status after the write.
  EXPECT_EQ(s["chunk1"]["chunk_result"], 1) << "ACCEPTED";
  EXPECT_EQ(s["chunk1"]["last_accepted"], 1);
  EXPECT_EQ(s["chunk1"]["next_line"], 4);
  EXPECT_EQ(s["duplicate"]["chunk_result"], 2) << "DUPLICATE";
  EXPECT_EQ(s["duplicate"]["last_accepted"], 1);
  EXPECT_EQ(s["duplicate"]["duplicates"], 1);
  EXPECT_EQ(s["duplicate"]["free_bytes"], s["chunk1"]["free_bytes"]) << "a duplicate is not queued again";
  EXPECT_EQ(s["gap"]["chunk_result"], 3) << "GAP";
  EXPECT_EQ(s["gap"]["last_accepted"], 1);
  EXPECT_EQ(s["gap"]["last_written"], 3);
  EXPECT_EQ(s["gap"]["free_bytes"], s["chunk1"]["free_bytes"]) << "a chunk after a gap is not queued";
  EXPECT_EQ(sim.stop(), 0) << sim.errors();
}

bool two_ptys(const std::string& text) {
  std::size_t n = 0, at = 0;
  while ((at = text.find("PTY is ", at)) != std::string::npos) {
    ++n;
    ++at;
  }
  return n >= 2;
}

TEST(ModbusPeers, MbpollOverRtuOnASocatPtyPair) {
  const std::string socat = require_program("socat");
  const std::string mbpoll = require_program("mbpoll");
  ASSERT_FALSE(socat.empty() || mbpoll.empty());
  // socat ignores the baud rate: this checks RTU framing, CRC and unit addressing, not timing.
  BackgroundProcess line({socat, "-d", "-d", "pty,raw,echo=0", "pty,raw,echo=0"});
  ASSERT_TRUE(line.wait_output(two_ptys, 10s)) << line.output();
  std::vector<std::string> ptys;
  static const std::regex pty(R"(PTY is (\S+))");
  for (auto it = std::sregex_iterator(line.output().begin(), line.output().end(), pty); it != std::sregex_iterator(); ++it)
    ptys.push_back((*it)[1]);
  ASSERT_EQ(ptys.size(), 2u) << line.output();

  SimProcess sim({"--machine", example_machine(), "--modbus-rtu", ptys[0], "--baud", "115200", "--parity", "N",
                  "--unit", "3"});
  const auto rtu = [&](std::vector<std::string> args, std::vector<std::string> values = {}) {
    std::vector<std::string> argv = {mbpoll, "-m", "rtu", "-b", "115200", "-P", "none", "-1", "-o", "1"};
    argv.insert(argv.end(), args.begin(), args.end());
    argv.push_back(ptys[1]);
    argv.insert(argv.end(), values.begin(), values.end());
    return run_peer(argv);
  };
  const PeerResult r = rtu({"-a", "3", "-t", "3", "-r", "1", "-c", "10"});
  ASSERT_EQ(r.exit_code, 0) << r.output << "\nsim stderr:\n" << sim.errors();
  const auto v = mbpoll_values(r.output);
  EXPECT_EQ(v.at(1), 1) << "protocol version";
  EXPECT_EQ(v.at(2), 0) << "state IDLE";

  // A command block written over RTU reaches the controller.
  const PeerResult w = rtu({"-a", "3", "-t", "4", "-r", "9"}, {"1", "1", "0", "0", "0", "9", "0", "4"});
  ASSERT_EQ(w.exit_code, 0) << w.output;
  const auto after = mbpoll_values(rtu({"-a", "3", "-t", "3", "-r", "1", "-c", "10"}).output);
  EXPECT_EQ(after.at(6), 1) << "command seq";
  EXPECT_EQ(after.at(5), 1) << "command result ACCEPTED";

  // Unit 4 is another device on the line: no answer.
  const PeerResult other = rtu({"-a", "4", "-t", "3", "-r", "1", "-c", "2"});
  EXPECT_NE(other.exit_code, 0) << other.output;
  EXPECT_EQ(sim.stop(), 0) << sim.errors();
}

}  // namespace
}  // namespace hybridctl::test
