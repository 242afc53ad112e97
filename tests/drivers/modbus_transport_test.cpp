// The Modbus transport (drivers/modbus_transport.hpp) against `hybridctl sim serve` run as a
// separate process: TCP and RTU (over a socat pty pair), with the simulator's fault
// injection (dropped connections, corrupt replies, busy exceptions, late replies).

#include <gtest/gtest.h>

#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <regex>

#include "common/error.hpp"
#include "drivers/modbus_transport.hpp"
#include "protocol/modbus_map.hpp"
#include "drivers/transport.hpp"
#include "sim_process.hpp"
#include "transport_fixtures.hpp"

namespace hybridctl::test {
namespace {

using drivers::TransportError;
using protocol::ControllerState;

std::vector<std::string> sim_args(std::initializer_list<std::string> extra, const std::string& report = {}) {
  std::vector<std::string> args = {"--machine", example_machine(), "--modbus", "tcp://127.0.0.1:0", "--time-scale",
                                   "0", "--heartbeat-timeout", "0"};
  args.insert(args.end(), extra);
  if (!report.empty()) args.insert(args.end(), {"--report", report});
  return args;
}

std::string tcp_uri(const SimProcess& sim) { return "modbus-tcp://127.0.0.1:" + std::to_string(sim.modbus_port()); }

drivers::TransportOptions quick_options() {
  drivers::TransportOptions o;
  o.response_timeout = std::chrono::milliseconds(500);
  o.reconnect_attempts = 5;
  o.reconnect_backoff = std::chrono::milliseconds(10);
  o.request_retries = 3;
  return o;
}

// A port nobody listens on (bound, then released).
int free_port() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr);
  socklen_t len = sizeof addr;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len);
  ::close(fd);
  return ntohs(addr.sin_port);
}

// Streams the program, waits for its end, and checks exactly-once delivery against the
// simulator's run report (written when it stops).
void stream_and_check(drivers::Transport& t, SimProcess& sim, const std::string& report, int moves, StreamOutcome& out) {
  const auto lines = program_of(moves);
  ASSERT_NO_FATAL_FAILURE(stream_program(t, lines, t.max_chunk_payload(), out));
  const protocol::Status s = wait_for_state(t, ControllerState::Completed);
  EXPECT_EQ(s.last_executed_line, lines.size());
  EXPECT_EQ(s.last_accepted_chunk, out.chunks);
  EXPECT_EQ(s.last_executed_chunk, out.chunks);
  EXPECT_EQ(s.refused_chunks, 0u);
  EXPECT_EQ(s.duplicate_chunks, out.duplicates);
  ASSERT_EQ(sim.stop(), 0) << sim.errors();
  const auto doc = read_json(report);
  // Every chunk queued exactly once, every line executed exactly once.
  EXPECT_EQ(doc["chunks"]["accepted"], out.chunks) << doc.dump(2);
  EXPECT_EQ(doc["chunks"]["executed"], out.chunks);
  EXPECT_EQ(doc["chunks"]["duplicates"], out.duplicates);
  EXPECT_EQ(doc["lines_executed"], lines.size());
  EXPECT_EQ(doc["program"]["completed"], true);
}

TEST(ModbusTcpTransport, ReadsTheStatusBlock) {
  SimProcess sim(sim_args({}));
  auto t = drivers::open_transport(tcp_uri(sim), quick_options());
  EXPECT_EQ(t->describe(), "modbus-tcp 127.0.0.1:" + std::to_string(sim.modbus_port()) + " unit 1");
  EXPECT_EQ(t->max_chunk_payload(), 222u);
  const protocol::Status s = t->read_status();
  EXPECT_EQ(s.protocol_version, 1);
  EXPECT_EQ(s.state, ControllerState::Idle);
  EXPECT_EQ(s.identity, 0u);
  EXPECT_EQ(s.boot_count, 1);
  EXPECT_EQ(s.free_buffer_bytes, 16384u);
  const auto c = t->counters();
  EXPECT_EQ(c.requests, 1u);
  EXPECT_EQ(c.timeouts + c.bad_replies + c.reconnects + c.retries, 0u);
}

TEST(ModbusTcpTransport, HeartbeatIsEchoed) {
  SimProcess sim(sim_args({}));
  auto t = drivers::open_transport(tcp_uri(sim), quick_options());
  t->send_heartbeat(4711);
  EXPECT_EQ(t->read_status().heartbeat_echo, 4711);
  t->send_heartbeat(4712);
  EXPECT_EQ(t->read_status().heartbeat_echo, 4712);
}

TEST(ModbusTcpTransport, SetProgramChunksAndStartShowInTheStatus) {
  const std::string dir = scratch_dir("modbus-tcp-stream");
  SimProcess sim(sim_args({}, dir + "/report.json"));
  auto t = drivers::open_transport(tcp_uri(sim), quick_options());
  StreamOutcome out;
  ASSERT_NO_FATAL_FAILURE(stream_and_check(*t, sim, dir + "/report.json", 400, out));
  EXPECT_GT(out.chunks, 40u);  // 400 lines of ~28 bytes in 222-byte chunks
  EXPECT_EQ(out.accepted, out.chunks);
  EXPECT_EQ(out.duplicates, 0u);
  const auto c = t->counters();
  EXPECT_EQ(c.timeouts + c.bad_replies + c.reconnects + c.retries, 0u);
}

TEST(ModbusTcpTransport, ReconnectsAfterTheServerDropsTheConnectionWithNoChunkLostOrDuplicated) {
  const std::string dir = scratch_dir("modbus-tcp-drop");
  SimProcess sim(sim_args({"--drop-every", "7"}, dir + "/report.json"));
  auto t = drivers::open_transport(tcp_uri(sim), quick_options());
  StreamOutcome out;
  ASSERT_NO_FATAL_FAILURE(stream_and_check(*t, sim, dir + "/report.json", 400, out));
  const auto doc = read_json(dir + "/report.json");
  const std::uint64_t dropped = doc["faults"]["injected"]["dropped"];
  EXPECT_GE(dropped, 5u);
  const auto c = t->counters();
  EXPECT_EQ(c.reconnects, dropped);
  EXPECT_EQ(c.retries, dropped);
  EXPECT_EQ(c.timeouts, 0u);
}

TEST(ModbusTcpTransport, ResendsAfterCorruptReplies) {
  const std::string dir = scratch_dir("modbus-tcp-corrupt");
  SimProcess sim(sim_args({"--corrupt-every", "5"}, dir + "/report.json"));
  auto t = drivers::open_transport(tcp_uri(sim), quick_options());
  StreamOutcome out;
  ASSERT_NO_FATAL_FAILURE(stream_and_check(*t, sim, dir + "/report.json", 400, out));
  const auto doc = read_json(dir + "/report.json");
  const std::uint64_t corrupted = doc["faults"]["injected"]["corrupted"];
  EXPECT_GE(corrupted, 5u);
  const auto c = t->counters();
  EXPECT_EQ(c.bad_replies, corrupted);
  EXPECT_EQ(c.retries, corrupted);
  // A chunk whose reply was damaged had arrived: its resend is acknowledged as a duplicate.
  EXPECT_GT(out.duplicates, 0u);
}

TEST(ModbusTcpTransport, ResendsAfterBusyExceptions) {
  const std::string dir = scratch_dir("modbus-tcp-busy");
  SimProcess sim(sim_args({"--exception-every", "4"}, dir + "/report.json"));
  auto t = drivers::open_transport(tcp_uri(sim), quick_options());
  StreamOutcome out;
  ASSERT_NO_FATAL_FAILURE(stream_and_check(*t, sim, dir + "/report.json", 200, out));
  const auto doc = read_json(dir + "/report.json");
  const std::uint64_t busy = doc["faults"]["injected"]["busy"];
  EXPECT_GE(busy, 5u);
  const auto c = t->counters();
  EXPECT_EQ(c.bad_replies, busy);
  EXPECT_EQ(c.retries, busy);
  // Busy means "not processed": no resend was a duplicate.
  EXPECT_EQ(out.duplicates, 0u);
}

TEST(ModbusTcpTransport, LateRepliesTimeOutAndTheCallFailsAfterItsResends) {
  SimProcess sim(sim_args({"--delay-ms", "400"}));
  auto options = quick_options();
  options.response_timeout = std::chrono::milliseconds(100);
  options.request_retries = 1;
  auto t = drivers::open_transport(tcp_uri(sim), options);
  try {
    t->read_status();
    FAIL() << "a reply 400 ms late passed a 100 ms timeout";
  } catch (const TransportError& e) {
    EXPECT_EQ(e.kind(), TransportError::Kind::Timeout) << e.what();
    EXPECT_NE(std::string(e.what()).find("no reply within the response timeout"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("after 1 resend"), std::string::npos) << e.what();
  }
  const auto c = t->counters();
  EXPECT_EQ(c.timeouts, 2u);
  EXPECT_EQ(c.retries, 1u);
  // With a timeout longer than the delay the same controller answers.
  options.response_timeout = std::chrono::milliseconds(1500);
  auto patient = drivers::open_transport(tcp_uri(sim), options);
  EXPECT_EQ(patient->read_status().state, ControllerState::Idle);
}

TEST(ModbusTcpTransport, NobodyListeningIsUnreachableAfterTheReconnectAttempts) {
  auto options = quick_options();
  options.reconnect_attempts = 3;
  options.reconnect_backoff = std::chrono::milliseconds(40);
  const auto start = std::chrono::steady_clock::now();
  try {
    drivers::open_transport("modbus-tcp://127.0.0.1:" + std::to_string(free_port()), options);
    FAIL() << "connected to a port nobody listens on";
  } catch (const TransportError& e) {
    EXPECT_EQ(e.kind(), TransportError::Kind::Unreachable);
    EXPECT_NE(std::string(e.what()).find("cannot connect (3 attempts): Connection refused"), std::string::npos)
        << e.what();
  }
  // Backoff 40 ms, then 80 ms: about 120 ms, far from the 2 s cap.
  const auto took = std::chrono::steady_clock::now() - start;
  EXPECT_GE(took, std::chrono::milliseconds(110));
  EXPECT_LT(took, std::chrono::milliseconds(2000));
}

TEST(ModbusTcpTransport, AControllerThatGoesAwayIsReportedUnreachable) {
  SimProcess sim(sim_args({}));
  auto options = quick_options();
  options.reconnect_attempts = 2;
  auto t = drivers::open_transport(tcp_uri(sim), options);
  EXPECT_EQ(t->read_status().state, ControllerState::Idle);
  ASSERT_EQ(sim.stop(), 0);
  try {
    t->read_status();
    FAIL() << "read a status from a stopped simulator";
  } catch (const TransportError& e) {
    EXPECT_EQ(e.kind(), TransportError::Kind::Unreachable) << e.what();
  }
  EXPECT_GE(t->counters().retries, 1u);
}

TEST(Transports, MalformedUrisAndSettingsAreInputErrors) {
  EXPECT_THROW(drivers::open_transport("modbus-tcp://127.0.0.1"), InputError);
  EXPECT_THROW(drivers::open_transport("http://127.0.0.1:80"), InputError);
  EXPECT_THROW(drivers::open_transport("socketcand://127.0.0.1:1"), InputError);  // no channel
  EXPECT_THROW(drivers::open_transport("modbus-rtu:///dev/null?baud=12345"), InputError);
  try {
    drivers::open_transport("modbus-tcp://127.0.0.1:502?unit=300");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("transport URI 'modbus-tcp://127.0.0.1:502?unit=300'"), std::string::npos)
        << e.what();
  }
  // libmodbus would silently run an unlisted rate at 9600: refused before it gets there.
  EXPECT_THROW(drivers::check_rtu_baud(14400), InputError);
  EXPECT_THROW(drivers::check_rtu_baud(4000001), InputError);
  EXPECT_NO_THROW(drivers::check_rtu_baud(115200));
  EXPECT_NO_THROW(drivers::check_rtu_baud(4000000));
  config::Transport rtu;
  rtu.kind = config::TransportKind::ModbusRtu;
  rtu.device = "/dev/null";
  rtu.baud = 250000;
  EXPECT_THROW(drivers::open_transport(rtu), InputError);
  config::Transport tcp;
  tcp.kind = config::TransportKind::ModbusTcp;
  tcp.host = "127.0.0.1";
  tcp.port = 502;
  tcp.unit = 250;  // libmodbus takes 0..247 and 255 over TCP
  EXPECT_THROW(drivers::open_transport(tcp), InputError);
}

// ---- RTU over a socat pty pair (socat ignores the baud rate: framing, CRC, units) ----

bool two_ptys(const std::string& text) {
  std::size_t n = 0, at = 0;
  while ((at = text.find("PTY is ", at)) != std::string::npos) {
    ++n;
    ++at;
  }
  return n >= 2;
}

std::vector<std::string> pty_pair(BackgroundProcess& line) {
  if (!line.wait_output(two_ptys, std::chrono::seconds(10))) return {};
  std::vector<std::string> ptys;
  static const std::regex pty(R"(PTY is (\S+))");
  for (auto it = std::sregex_iterator(line.output().begin(), line.output().end(), pty); it != std::sregex_iterator(); ++it)
    ptys.push_back((*it)[1]);
  return ptys;
}

TEST(ModbusRtuTransport, StreamsAProgramOverASocatPtyPair) {
  const std::string socat = require_program("socat");
  ASSERT_FALSE(socat.empty());
  BackgroundProcess line({socat, "-d", "-d", "pty,raw,echo=0", "pty,raw,echo=0"});
  const auto ptys = pty_pair(line);
  ASSERT_EQ(ptys.size(), 2u) << line.output();
  const std::string dir = scratch_dir("modbus-rtu-stream");
  SimProcess sim({"--machine", example_machine(), "--modbus-rtu", ptys[0], "--baud", "115200", "--parity", "N",
                  "--unit", "3", "--time-scale", "0", "--heartbeat-timeout", "0", "--report", dir + "/report.json"});
  auto t = drivers::open_transport("modbus-rtu://" + ptys[1] + "?baud=115200&parity=N&unit=3", quick_options());
  EXPECT_EQ(t->describe(), "modbus-rtu " + ptys[1] + " 115200 8N1 unit 3");
  EXPECT_EQ(t->read_status().state, ControllerState::Idle);
  t->send_heartbeat(9);
  EXPECT_EQ(t->read_status().heartbeat_echo, 9);
  StreamOutcome out;
  ASSERT_NO_FATAL_FAILURE(stream_and_check(*t, sim, dir + "/report.json", 150, out));
  EXPECT_EQ(out.duplicates, 0u);
}

TEST(ModbusRtuTransport, ResendsAfterRepliesWithABadCrc) {
  const std::string socat = require_program("socat");
  ASSERT_FALSE(socat.empty());
  BackgroundProcess line({socat, "-d", "-d", "pty,raw,echo=0", "pty,raw,echo=0"});
  const auto ptys = pty_pair(line);
  ASSERT_EQ(ptys.size(), 2u) << line.output();
  const std::string dir = scratch_dir("modbus-rtu-corrupt");
  SimProcess sim({"--machine", example_machine(), "--modbus-rtu", ptys[0], "--baud", "115200", "--parity", "E",
                  "--time-scale", "0", "--heartbeat-timeout", "0", "--corrupt-every", "4", "--report",
                  dir + "/report.json"});
  auto t = drivers::open_transport("modbus-rtu://" + ptys[1] + "?baud=115200", quick_options());
  StreamOutcome out;
  ASSERT_NO_FATAL_FAILURE(stream_and_check(*t, sim, dir + "/report.json", 100, out));
  const auto doc = read_json(dir + "/report.json");
  const std::uint64_t corrupted = doc["faults"]["injected"]["corrupted"];
  EXPECT_GE(corrupted, 3u);
  EXPECT_EQ(t->counters().bad_replies, corrupted);
  EXPECT_EQ(t->counters().reconnects, 0u);  // a serial line is flushed, not reopened
}

TEST(ModbusRtuTransport, AnotherUnitDoesNotAnswer) {
  const std::string socat = require_program("socat");
  ASSERT_FALSE(socat.empty());
  BackgroundProcess line({socat, "-d", "-d", "pty,raw,echo=0", "pty,raw,echo=0"});
  const auto ptys = pty_pair(line);
  ASSERT_EQ(ptys.size(), 2u) << line.output();
  SimProcess sim({"--machine", example_machine(), "--modbus-rtu", ptys[0], "--baud", "115200", "--unit", "3"});
  auto options = quick_options();
  options.response_timeout = std::chrono::milliseconds(150);
  options.request_retries = 1;
  auto t = drivers::open_transport("modbus-rtu://" + ptys[1] + "?baud=115200&unit=4", options);
  try {
    t->read_status();
    FAIL() << "unit 4 answered";
  } catch (const TransportError& e) {
    EXPECT_EQ(e.kind(), TransportError::Kind::Timeout) << e.what();
  }
  EXPECT_EQ(t->counters().timeouts, 2u);
}

}  // namespace
}  // namespace hybridctl::test
