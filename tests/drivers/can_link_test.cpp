// CanTransport (drivers/can_link.hpp) over a scripted bus: which status snapshot a call
// returns. A snapshot that arrived since the last one returned is news and comes back at
// once; with none, the call waits for the next (and times out on a silent bus).

#include <gtest/gtest.h>

#include <deque>

#include "drivers/can_link.hpp"
#include "protocol/can_frames.hpp"

namespace hybridctl::drivers {
namespace {

namespace can = protocol::can;
constexpr std::uint8_t kNode = 1;

// Frames the test queued arrive one per receive(), at once; nothing else ever does.
class ScriptedBus final : public CanFrameIo {
 public:
  explicit ScriptedBus(std::deque<can::CanFrame>& incoming) : incoming_(incoming) {}
  std::string describe() const override { return "scripted bus"; }
  void open(std::chrono::milliseconds) override { open_ = true; }
  void close() override { open_ = false; }
  bool is_open() const override { return open_; }
  void send(std::span<const can::CanFrame>) override {}
  std::optional<can::CanFrame> receive(SteadyTime) override {
    if (incoming_.empty()) return std::nullopt;
    const can::CanFrame f = incoming_.front();
    incoming_.pop_front();
    return f;
  }
  std::uint64_t garbage() const override { return 0; }

 private:
  std::deque<can::CanFrame>& incoming_;
  bool open_ = false;
};

void queue_snapshot(std::deque<can::CanFrame>& bus, std::uint16_t heartbeat_echo, std::uint8_t counter) {
  protocol::Status s;
  s.heartbeat_echo = heartbeat_echo;
  for (const auto& f : can::encode_status_frames(s, counter, kNode)) bus.push_back(f);
}

TransportOptions no_retries() {
  TransportOptions o;
  o.response_timeout = std::chrono::milliseconds(20);
  o.request_retries = 0;
  return o;
}

TEST(CanTransport, ReadStatusReturnsASnapshotThatArrivedSinceTheLastOneReturned) {
  std::deque<can::CanFrame> bus;
  queue_snapshot(bus, 7, 0);
  CanTransport t(std::make_unique<ScriptedBus>(bus), kNode, no_retries());
  EXPECT_EQ(t.read_status().heartbeat_echo, 7);

  // Nothing new since: the call waits for the next snapshot, which never comes.
  try {
    t.read_status();
    FAIL() << "the same snapshot was returned twice";
  } catch (const TransportError& e) {
    EXPECT_EQ(e.kind(), TransportError::Kind::Timeout) << e.what();
  }

  queue_snapshot(bus, 8, 1);
  EXPECT_EQ(t.read_status().heartbeat_echo, 8);
}

TEST(CanTransport, ReadStatusReturnsTheNewestOfTheSnapshotsThatArrived) {
  std::deque<can::CanFrame> bus;
  queue_snapshot(bus, 1, 0);
  CanTransport t(std::make_unique<ScriptedBus>(bus), kNode, no_retries());
  EXPECT_EQ(t.read_status().heartbeat_echo, 1);
  queue_snapshot(bus, 2, 1);
  queue_snapshot(bus, 3, 2);
  EXPECT_EQ(t.read_status().heartbeat_echo, 3);
}

}  // namespace
}  // namespace hybridctl::drivers
