// The CAN transports against `hybridctl sim serve` run as a separate process: socketcand
// (the text protocol over TCP; with the simulator's fault injection: damaged frame text,
// refused transfers, dropped connections) and kernel SocketCAN (which this kernel lacks:
// the test checks the transport says so, then skips).

#include <gtest/gtest.h>

#include <net/if.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <thread>

#include "protocol/can_transfer.hpp"
#include "drivers/socketcan_transport.hpp"
#include "drivers/transport.hpp"
#include "sim_process.hpp"
#include "transport_fixtures.hpp"

namespace hybridctl::test {
namespace {

using drivers::TransportError;
using protocol::ControllerState;

std::vector<std::string> sim_args(std::initializer_list<std::string> extra, const std::string& report = {}) {
  std::vector<std::string> args = {"--machine", example_machine(), "--socketcand", "127.0.0.1:0", "--time-scale", "0",
                                   "--heartbeat-timeout", "0"};
  args.insert(args.end(), extra);
  if (!report.empty()) args.insert(args.end(), {"--report", report});
  return args;
}

std::string uri(const SimProcess& sim, int node = 1) {
  return "socketcand://127.0.0.1:" + std::to_string(sim.socketcand_port()) + "/can0?node=" + std::to_string(node);
}

drivers::TransportOptions quick_options() {
  drivers::TransportOptions o;
  o.response_timeout = std::chrono::milliseconds(500);
  o.reconnect_attempts = 5;
  o.reconnect_backoff = std::chrono::milliseconds(10);
  o.request_retries = 3;
  return o;
}

void stream_and_check(drivers::Transport& t, SimProcess& sim, const std::string& report, int moves,
                      std::size_t max_payload, StreamOutcome& out) {
  const auto lines = program_of(moves);
  ASSERT_NO_FATAL_FAILURE(stream_program(t, lines, max_payload, out));
  const protocol::Status s = wait_for_state(t, ControllerState::Completed);
  EXPECT_EQ(s.last_executed_line, lines.size());
  EXPECT_EQ(s.last_accepted_chunk, out.chunks);
  EXPECT_EQ(s.refused_chunks, 0u);
  EXPECT_EQ(s.duplicate_chunks, out.duplicates);
  ASSERT_EQ(sim.stop(), 0) << sim.errors();
  const auto doc = read_json(report);
  EXPECT_EQ(doc["chunks"]["accepted"], out.chunks) << doc.dump(2);
  EXPECT_EQ(doc["chunks"]["executed"], out.chunks);
  EXPECT_EQ(doc["lines_executed"], lines.size());
  EXPECT_EQ(doc["program"]["completed"], true);
}

TEST(SocketcandTransport, ReadsTheStatusFromTheControllersSnapshots) {
  SimProcess sim(sim_args({"--node", "5"}));
  auto t = drivers::open_transport(uri(sim, 5), quick_options());
  EXPECT_EQ(t->describe(),
            "socketcand 127.0.0.1:" + std::to_string(sim.socketcand_port()) + " channel can0 node 5");
  EXPECT_EQ(t->max_chunk_payload(), protocol::can::kMaxChunkPayload);
  const protocol::Status s = t->read_status();
  EXPECT_EQ(s.state, ControllerState::Idle);
  EXPECT_EQ(s.boot_count, 1);
  t->send_heartbeat(321);
  // The heartbeat is a frame with no answer; a later snapshot shows it.
  protocol::Status echo = t->read_status();
  for (int i = 0; i < 5 && echo.heartbeat_echo != 321; ++i) echo = t->read_status();
  EXPECT_EQ(echo.heartbeat_echo, 321);
  const auto c = t->counters();
  EXPECT_EQ(c.timeouts + c.bad_replies + c.reconnects + c.retries, 0u);
}

TEST(SocketcandTransport, AnotherNodeIsSilent) {
  SimProcess sim(sim_args({"--node", "5"}));
  auto options = quick_options();
  options.response_timeout = std::chrono::milliseconds(200);
  options.request_retries = 0;
  auto t = drivers::open_transport(uri(sim, 6), options);
  try {
    t->read_status();
    FAIL() << "node 6 answered for node 5";
  } catch (const TransportError& e) {
    EXPECT_EQ(e.kind(), TransportError::Kind::Timeout) << e.what();
  }
}

TEST(SocketcandTransport, StreamsWholeChunksPacedByFlowControl) {
  const std::string dir = scratch_dir("socketcand-stream");
  // A controller that grants 8 frames per flow control (the default grants a whole chunk).
  SimProcess sim(sim_args({"--can-block-size", "8"}, dir + "/report.json"));
  auto t = drivers::open_transport(uri(sim), quick_options());
  StreamOutcome out;
  // 4075-byte chunks: 584 frames each, a flow control every 8.
  ASSERT_NO_FATAL_FAILURE(stream_and_check(*t, sim, dir + "/report.json", 900, t->max_chunk_payload(), out));
  EXPECT_GE(out.chunks, 6u);
  EXPECT_EQ(out.duplicates, 0u);
  const auto c = t->counters();
  EXPECT_EQ(c.timeouts + c.bad_replies + c.reconnects + c.retries, 0u);
}

TEST(SocketcandTransport, SkipsDamagedFrameText) {
  const std::string dir = scratch_dir("socketcand-corrupt");
  SimProcess sim(sim_args({"--corrupt-every", "97"}, dir + "/report.json"));
  auto t = drivers::open_transport(uri(sim), quick_options());
  StreamOutcome out;
  ASSERT_NO_FATAL_FAILURE(stream_and_check(*t, sim, dir + "/report.json", 300, 400, out));
  const auto doc = read_json(dir + "/report.json");
  EXPECT_GE(doc["faults"]["injected"]["corrupted"].get<std::uint64_t>(), 5u);
  // A damaged status frame spoils its snapshot, a damaged flow control stalls a transfer
  // until its timeout: either way the call waits for the next one or resends.
  EXPECT_GE(t->counters().bad_replies, 5u);
}

TEST(SocketcandTransport, ResendsATransferTheControllerRefused) {
  const std::string dir = scratch_dir("socketcand-refused");
  SimProcess sim(sim_args({"--exception-every", "3"}, dir + "/report.json"));
  auto t = drivers::open_transport(uri(sim), quick_options());
  StreamOutcome out;
  ASSERT_NO_FATAL_FAILURE(stream_and_check(*t, sim, dir + "/report.json", 300, 300, out));
  const auto doc = read_json(dir + "/report.json");
  const std::uint64_t refused = doc["faults"]["injected"]["busy"];
  EXPECT_GE(refused, 5u);
  EXPECT_EQ(t->counters().retries, refused);
  EXPECT_EQ(out.duplicates, 0u);  // a refused transfer queued nothing
}

TEST(SocketcandTransport, ReconnectsAfterTheServerDropsTheConnection) {
  const std::string dir = scratch_dir("socketcand-drop");
  SimProcess sim(sim_args({"--drop-every", "60"}, dir + "/report.json"));
  auto t = drivers::open_transport(uri(sim), quick_options());
  StreamOutcome out;
  // Chunks of at most 60 payload bytes: 12 frames each, so most get through between drops.
  ASSERT_NO_FATAL_FAILURE(stream_and_check(*t, sim, dir + "/report.json", 150, 60, out));
  const auto doc = read_json(dir + "/report.json");
  const std::uint64_t dropped = doc["faults"]["injected"]["dropped"];
  EXPECT_GE(dropped, 5u);
  EXPECT_EQ(t->counters().reconnects, dropped);
}

TEST(SocketcandTransport, ARepeatedCommandIsANoOp) {
  SimProcess sim(sim_args({}));
  auto t = drivers::open_transport(uri(sim), quick_options());
  const auto lines = program_of(10);
  const protocol::Command set{protocol::CommandCode::SetProgram, 7, protocol::program_identity(lines),
                              static_cast<std::uint32_t>(lines.size())};
  protocol::Status s = t->send_command(set);
  EXPECT_EQ(s.command_seq, 7);
  EXPECT_EQ(s.command_result, protocol::ResultCode::Accepted);
  const protocol::Command start{protocol::CommandCode::Start, 8, 0, 0};
  s = t->send_command(start);
  EXPECT_EQ(s.command_seq, 8);
  EXPECT_EQ(s.state, ControllerState::Running);
  // SET_PROGRAM with a new seq is refused while running; sent again with that seq it is ignored
  // (the status keeps the first outcome).
  s = t->send_command(protocol::Command{protocol::CommandCode::SetProgram, 9, set.identity, set.line_count});
  EXPECT_EQ(s.command_seq, 9);
  EXPECT_EQ(s.command_result, protocol::ResultCode::WrongState);
  s = t->send_command(protocol::Command{protocol::CommandCode::SetProgram, 9, set.identity, set.line_count});
  EXPECT_EQ(s.command_seq, 9);
  EXPECT_EQ(s.command_result, protocol::ResultCode::WrongState);
  EXPECT_EQ(s.state, ControllerState::Running);
}

TEST(SocketcandTransport, APeerThatIsNotSocketcandIsAProtocolError) {
  // A one-shot server greeting with something else.
  const int listener = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(::bind(listener, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
  ASSERT_EQ(::listen(listener, 1), 0);
  socklen_t len = sizeof addr;
  ::getsockname(listener, reinterpret_cast<sockaddr*>(&addr), &len);
  std::thread server([listener] {
    const int c = ::accept(listener, nullptr, nullptr);
    if (c < 0) return;
    const char greeting[] = "SSH-2.0-OpenSSH_9.2\r\n< hello >";
    (void)!::write(c, greeting, sizeof greeting - 1);
    char buf[64];
    (void)!::read(c, buf, sizeof buf);
    ::close(c);
  });
  try {
    drivers::open_transport("socketcand://127.0.0.1:" + std::to_string(ntohs(addr.sin_port)) + "/can0", quick_options());
    ADD_FAILURE() << "took a peer that said < hello > for socketcand";
  } catch (const TransportError& e) {
    EXPECT_EQ(e.kind(), TransportError::Kind::Protocol) << e.what();
    EXPECT_NE(std::string(e.what()).find("expected the greeting < hi >, got < hello >"), std::string::npos) << e.what();
  }
  server.join();
  ::close(listener);
}

// ---- kernel SocketCAN ----

TEST(SocketCanTransport, StreamsOverAKernelCanInterfaceOrSaysTheKernelHasNone) {
  try {
    auto probe = drivers::open_transport("socketcan://vcan0", quick_options());
  } catch (const TransportError& e) {
    if (e.kind() == TransportError::Kind::Unsupported) {
      EXPECT_FALSE(drivers::kernel_has_socketcan());
      EXPECT_NE(std::string(e.what()).find("this kernel has no SocketCAN (AF_CAN)"), std::string::npos) << e.what();
      GTEST_SKIP() << "this kernel has no SocketCAN (socket(AF_CAN) fails with EAFNOSUPPORT), so the SocketCAN "
                      "transport cannot run here; the same CAN logic is tested over socketcand. Message: "
                   << e.what();
    }
    ASSERT_NE(::if_nametoindex("vcan0"), 0u)
        << "this kernel has SocketCAN but no vcan0: modprobe vcan; ip link add vcan0 type vcan; ip link set vcan0 up ("
        << e.what() << ")";
  }
  // A kernel with CAN and a vcan0: the simulator's SocketCAN endpoint on it.
  const std::string dir = scratch_dir("socketcan-stream");
  SimProcess sim({"--machine", example_machine(), "--socketcan", "vcan0", "--time-scale", "0", "--heartbeat-timeout",
                  "0", "--report", dir + "/report.json"});
  auto t = drivers::open_transport("socketcan://vcan0", quick_options());
  StreamOutcome out;
  const auto lines = program_of(200);
  ASSERT_NO_FATAL_FAILURE(stream_program(*t, lines, t->max_chunk_payload(), out));
  const protocol::Status s = wait_for_state(*t, ControllerState::Completed);
  EXPECT_EQ(s.last_executed_line, lines.size());
}

}  // namespace
}  // namespace hybridctl::test
