// `hybridctl sim serve --socketcand`: python-can 4.1's socketcand interface as the peer,
// garbage on the port next to a well-behaved client, bus pacing; and the text protocol's
// parser and the frame-time model in process.

#include <gtest/gtest.h>

#include <map>
#include <random>
#include <regex>
#include <sstream>

#include "protocol/can_frames.hpp"
#include "sim/wire/can_node.hpp"
#include "sim/wire/socketcand_server.hpp"
#include "sim_process.hpp"
#include "wire_client.hpp"

namespace hybridctl::test {
namespace {

using sim::wire::parse_socketcand_element;
using Kind = sim::wire::SocketcandRequest::Kind;

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

TEST(Socketcand, PythonCanSeesStatusAndItsCommandHeartbeatAndChunkTakeEffect) {
  const std::string python = require_program("/usr/bin/python3");
  ASSERT_FALSE(python.empty());
  const PeerResult has_can = run_peer({python, "-c", "import can.interfaces.socketcand"});
  ASSERT_EQ(has_can.exit_code, 0) << "python-can is missing (run scripts/setup): " << has_can.output;

  // A slower status period keeps the snapshots apart (python-can loses a frame split
  // across its 1024-byte reads).
  SimProcess sim({"--machine", example_machine(), "--socketcand", "127.0.0.1:0", "--node", "5", "--status-period-ms",
                  "100"});
  ASSERT_GT(sim.socketcand_port(), 0);
  const PeerResult r =
      run_peer({python, std::string(HYBRIDCTL_SOURCE_DIR) + "/tests/sim/peers/python_can_socketcand.py", "127.0.0.1",
                std::to_string(sim.socketcand_port()), "5"});
  ASSERT_EQ(r.exit_code, 0) << r.output << "\nsim stderr:\n" << sim.errors();
  auto s = step_values(r.output);
  ASSERT_EQ(s.count("chunk1"), 1u) << r.output;
  EXPECT_EQ(s["status"]["version"], 1);
  EXPECT_EQ(s["status"]["state"], 0);
  EXPECT_EQ(s["set_program"]["command_seq"], 1);
  EXPECT_EQ(s["set_program"]["command_code"], 1);
  EXPECT_EQ(s["set_program"]["command_result"], 1) << "ACCEPTED";
  EXPECT_EQ(s["set_program"]["program_lines"], 6);
  EXPECT_EQ(s["heartbeat"]["heartbeat_echo"], 0x1234);
  EXPECT_EQ(s["chunk1"]["chunk_result"], 1) << "ACCEPTED";
  EXPECT_EQ(s["chunk1"]["last_accepted"], 1);
  EXPECT_EQ(s["chunk1"]["next_line"], 5);
  EXPECT_EQ(sim.stop(), 0) << sim.errors();
}

// A minimal socketcand client (the text protocol by hand), for what no library sends.
struct TextClient {
  explicit TextClient(int port) : socket(port) {}
  bool open_raw() {
    if (socket.receive(2s, "< hi >") != "< hi >") return false;
    socket.send("< open can0 >");
    if (socket.receive(2s, "< ok >") != "< ok >") return false;
    socket.send("< rawmode >");
    return socket.receive(2s, "< ok >") == "< ok >";
  }
  RawSocket socket;
};

TEST(Socketcand, GarbageGetsAnErrorQueuesNothingAndTheOtherClientIsServed) {
  SimProcess sim({"--machine", example_machine(), "--socketcand", "127.0.0.1:0"});
  const int port = sim.socketcand_port();
  TextClient good(port);
  ASSERT_TRUE(good.open_raw());
  EXPECT_NE(good.socket.receive(2s, "< frame 181 ").find("< frame 181 "), std::string::npos) << "status frames";

  TextClient bad(port);
  EXPECT_EQ(bad.socket.receive(2s, "< hi >"), "< hi >");
  bad.socket.send("this is not socketcand\n");
  EXPECT_NE(bad.socket.receive(2s, " >").find("< error "), std::string::npos);
  bad.socket.send("< send 101 8 1 0 1 13 0 0 0 0 >");  // before < open >
  EXPECT_NE(bad.socket.receive(2s, " >").find("< error "), std::string::npos);
  bad.socket.send("< open can0 >");
  EXPECT_EQ(bad.socket.receive(2s, "< ok >"), "< ok >");
  // SET_PROGRAM frames, each broken a different way: none may reach the controller.
  for (const char* broken : {"< send 101 9 1 0 1 13 0 0 0 0 >", "< send 101 8 1 0 1 13 0 0 0 >",
                             "< send 101 8 1 0 1 13 0 0 0 zz >", "< send 101 8 1 0 1 13 0 0 0 100 >",
                             "< send 1 0 1 13 0 0 0 0 >", "< sned 101 8 1 0 1 13 0 0 0 0 >", "< >"}) {
    bad.socket.send(broken);
    const std::string answer = bad.socket.receive(2s, " >");
    EXPECT_EQ(answer.rfind("< error ", 0), 0u) << broken << " -> " << answer;
  }
  bad.socket.send("<<<<<");
  EXPECT_NE(bad.socket.receive(2s, " >").find("< error "), std::string::npos);

  // The good client still gets status snapshots, and they show no command arrived.
  protocol::can::StatusAssembler assembler(1);
  std::optional<protocol::Status> status;
  std::string text;
  const auto end = std::chrono::steady_clock::now() + 3s;
  static const std::regex frame(R"(< frame ([0-9A-F]+) (\d+)\.(\d+) ([0-9A-F]*) >)");
  while (!status && std::chrono::steady_clock::now() < end) {
    text += good.socket.receive(200ms);
    std::smatch m;
    while (!status && std::regex_search(text, m, frame)) {
      protocol::can::CanFrame f;
      f.id = static_cast<std::uint32_t>(std::stoul(m[1], nullptr, 16));
      const std::string hex = m[4];
      f.len = static_cast<std::uint8_t>(hex.size() / 2);
      for (std::size_t i = 0; i < f.len; ++i) f.data[i] = static_cast<std::uint8_t>(std::stoul(hex.substr(2 * i, 2), nullptr, 16));
      if (f.id == protocol::can::status_id(1)) status = assembler.on_frame(f).status;
      text = m.suffix();
    }
  }
  ASSERT_TRUE(status.has_value()) << "no whole status snapshot reached the good client";
  EXPECT_EQ(status->command_seq, 0) << "a refused element must not put anything on the bus";
  EXPECT_EQ(sim.stop(), 0) << sim.errors();
}

TEST(Socketcand, PacedBusSpreadsASnapshotOverItsFrameTimes) {
  // At 125 kbit/s a status snapshot (15 frames of 8 bytes and one of 4) takes >= 16 ms.
  SimProcess sim({"--machine", example_machine(), "--socketcand", "127.0.0.1:0", "--can-bitrate", "125000"});
  TextClient client(sim.socketcand_port());
  ASSERT_TRUE(client.open_raw());
  std::string text;
  const auto end = std::chrono::steady_clock::now() + 3s;
  static const std::regex frame(R"(< frame 181 (\d+)\.(\d+) ([0-9A-F]{4})([0-9A-F]*) >)");
  double first = -1, last = -1;
  while (last < 0 && std::chrono::steady_clock::now() < end) {
    text += client.socket.receive(100ms);
    std::smatch m;
    while (last < 0 && std::regex_search(text, m, frame)) {
      const int index = std::stoi(m[3].str().substr(0, 2), nullptr, 16);
      const double t = std::stod(m[1]) + std::stod(m[2]) * 1e-6;
      if (index == 0) first = t;
      if (index == 15 && first >= 0) last = t;
      text = m.suffix();
    }
  }
  ASSERT_GE(last, 0) << "no whole snapshot";
  const double expected = 15 * sim::wire::can_frame_time(8, 125000).count() * 1e-6;  // from frame 0's end to frame 15's
  EXPECT_GE(last - first, 0.8 * expected) << "frames came faster than the bus carries them";
  EXPECT_LT(last - first, 0.05);
  EXPECT_EQ(sim.stop(), 0) << sim.errors();
}

TEST(SocketcandText, ParsesWhatClientsSend) {
  auto open = parse_socketcand_element("< open can0 >");
  ASSERT_TRUE(open.request.has_value()) << open.error;
  EXPECT_EQ(open.request->kind, Kind::Open);
  EXPECT_EQ(open.request->channel, "can0");
  EXPECT_EQ(parse_socketcand_element("< rawmode >").request->kind, Kind::RawMode);
  EXPECT_EQ(parse_socketcand_element("<echo>").request->kind, Kind::Echo);

  // python-can: ID and length in upper-case hex, bytes as unpadded lower-case hex.
  auto send = parse_socketcand_element("< send 201 8 10 14 1 0 0 0 1 a >");
  ASSERT_TRUE(send.request.has_value()) << send.error;
  EXPECT_EQ(send.request->kind, Kind::Send);
  EXPECT_EQ(send.request->frame.id, 0x201u);
  EXPECT_EQ(send.request->frame.len, 8);
  EXPECT_EQ(send.request->frame.data[0], 0x10);
  EXPECT_EQ(send.request->frame.data[7], 0x0A);
  auto empty = parse_socketcand_element("< send 701 0 >");
  ASSERT_TRUE(empty.request.has_value());
  EXPECT_EQ(empty.request->frame.len, 0);
}

TEST(SocketcandText, RefusesMalformedElementsSayingWhy) {
  for (const char* bad : {"< send 201 9 1 2 3 4 5 6 7 8 9 >", "< send 201 2 1 >", "< send 201 1 1ff >",
                          "< send 201 1 g >", "< send 200000000 0 >", "< send >", "< open >",
                          "< open a-bus-name-that-is-too-long >", "< open can0 extra >", "< rawmode now >",
                          "< hello >", "<>", "< send 201 x >"}) {
    const auto p = parse_socketcand_element(bad);
    EXPECT_FALSE(p.request.has_value()) << bad;
    EXPECT_FALSE(p.error.empty()) << bad;
    EXPECT_EQ(p.error.find_first_of("<>"), std::string::npos) << "the error text goes inside < error ... >: " << p.error;
  }
}

TEST(SocketcandText, SplitsAClientStreamIntoElementsAndWhatIsRefused) {
  using K = sim::wire::SocketcandPiece::Kind;
  const std::string in = "  < open can0 >junk <send 123 0 ><unclosed < rawmode >\n< partial";
  std::vector<std::pair<K, std::string>> pieces;
  const std::size_t used = sim::wire::split_socketcand_stream(in, 256, [&](const sim::wire::SocketcandPiece& p) {
    pieces.emplace_back(p.kind, std::string(p.text));
    return true;
  });
  const std::vector<std::pair<K, std::string>> expected = {{K::Element, "< open can0 >"},
                                                           {K::Garbage, "junk "},
                                                           {K::Element, "<send 123 0 >"},
                                                           {K::Unclosed, "<unclosed "},
                                                           {K::Element, "< rawmode >"}};
  EXPECT_EQ(pieces, expected);
  EXPECT_EQ(in.substr(used), "< partial") << "an element not yet closed waits for more input";

  // Too long to be an element: given up on; a false from the callback stops the split.
  const std::string overlong = "<" + std::string(300, 'x');
  pieces.clear();
  EXPECT_EQ(sim::wire::split_socketcand_stream(overlong, 256, [&](const sim::wire::SocketcandPiece& p) {
              pieces.emplace_back(p.kind, std::string(p.text));
              return true;
            }),
            overlong.size());
  ASSERT_EQ(pieces.size(), 1u);
  EXPECT_EQ(pieces[0].first, K::Overlong);
  EXPECT_EQ(sim::wire::split_socketcand_stream("<echo><echo>", 256, [](const sim::wire::SocketcandPiece&) { return false; }), 6u);
}

TEST(SocketcandText, FormatsFramesAsTheDaemonDoes) {
  protocol::can::CanFrame f;
  f.id = 0x181;
  f.len = 3;
  f.data[0] = 0x00;
  f.data[1] = 0xAB;
  f.data[2] = 0x5;
  EXPECT_EQ(sim::wire::format_socketcand_frame(f, 1700000000, 42), "< frame 181 1700000000.000042 00AB05 >");
  f.id = 0x12345;
  f.len = 0;
  EXPECT_EQ(sim::wire::format_socketcand_frame(f, 1, 999999), "< frame 00012345 1.999999  >");
}

TEST(CanBusTiming, FrameTimesFollowTheBitCount) {
  // 47 framing bits + 8 per byte + worst-case stuffing floor((34 + 8n - 1) / 4).
  EXPECT_EQ(sim::wire::can_frame_time(8, 1'000'000).count(), 135);  // 111 + 24 bits
  EXPECT_EQ(sim::wire::can_frame_time(0, 1'000'000).count(), 55);   // 47 + 8 bits
  EXPECT_EQ(sim::wire::can_frame_time(4, 1'000'000).count(), 95);   // 79 + 16 bits
  EXPECT_EQ(sim::wire::can_frame_time(8, 500'000).count(), 270);
  EXPECT_EQ(sim::wire::can_frame_time(8, 0).count(), 0);
  sim::wire::CanBusClock bus(1'000'000);
  const sim::wire::CanMicros t0{1000};
  EXPECT_EQ(bus.reserve(t0, 8).count(), 1135);
  EXPECT_EQ(bus.reserve(t0, 8).count(), 1270) << "a frame waits for the one before it";
  EXPECT_EQ(bus.reserve(sim::wire::CanMicros{5000}, 0).count(), 5055) << "an idle bus starts at once";
}

TEST(Socketcand, RandomTextNeverTakesTheServerDown) {
  SimProcess sim({"--machine", example_machine(), "--socketcand", "127.0.0.1:0", "--time-scale", "0"});
  TextClient good(sim.socketcand_port());
  ASSERT_TRUE(good.open_raw());
  std::mt19937 random(7);
  const std::string alphabet = "<> sendopenrawmodeecho0123456789abcdefABCDEF\n\t\x01\xff";
  for (int i = 0; i < 200; ++i) {
    TextClient raw(sim.socketcand_port());
    raw.socket.receive(200ms, "< hi >");
    std::string text = i % 3 == 0 ? "< open can0 >< rawmode >" : "";
    const std::size_t n = 1 + random() % 400;
    for (std::size_t k = 0; k < n; ++k) text += alphabet[random() % alphabet.size()];
    if (i % 5 == 0) {  // frames that are well formed but random: whatever they say, on the bus they go
      text += "< send " + std::to_string(0x100 + random() % 0x700) + " 8";
      for (int b = 0; b < 8; ++b) text += " " + std::to_string(random() % 100);
      text += " >";
    }
    raw.socket.send(text);
    raw.socket.receive(5ms);
  }
  good.socket.receive(200ms);  // drain
  EXPECT_NE(good.socket.receive(2s, "< frame 181 ").find("< frame 181 "), std::string::npos)
      << "the good client still gets status frames";
  EXPECT_EQ(sim.stop(), 0) << sim.errors();
}

}  // namespace
}  // namespace hybridctl::test
