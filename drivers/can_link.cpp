#include "drivers/can_link.hpp"

#include <algorithm>
#include <random>
#include <utility>
#include <variant>
#include <vector>

#include "common/error.hpp"
#include "drivers/backoff.hpp"

namespace hybridctl::drivers {

namespace can = protocol::can;
using Kind = TransportError::Kind;
using std::chrono::milliseconds;

namespace {

can::Micros now_micros() {
  return std::chrono::duration_cast<can::Micros>(SteadyClock::now().time_since_epoch());
}

SteadyTime to_steady(can::Micros t) { return SteadyTime(std::chrono::duration_cast<SteadyClock::duration>(t)); }

// Frames at most taken in one drain, so a flooded bus cannot hold a call forever.
constexpr int kMaxDrainFrames = 4096;

// After a transfer whose first flow control never came (the segmenter waited the
// protocol's 1000 ms), this much more passes before the chunk is resent, so that the
// controller's reassembler (which drops a transfer 1000 ms after its last frame) has
// dropped it and does not take the resent first frame for a repeat of the old one.
constexpr std::chrono::milliseconds kResendMargin{150};
// Every resend after a transfer timeout waits a random 0..kResendJitterMs ms more.
constexpr unsigned kResendJitterMs = 100;

}  // namespace

struct CanTransport::Issue {
  Kind kind;
  std::string message;
};

CanTransport::CanTransport(std::unique_ptr<CanFrameIo> io, std::uint8_t node, const TransportOptions& options)
    : io_(std::move(io)), node_(node), options_(options), assembler_(node) {
  if (!can::valid_node(node)) throw InputError(io_->describe() + ": node " + std::to_string(node) + ": expected 1..127");
  ensure_open();
}

CanTransport::~CanTransport() { io_->close(); }

std::string CanTransport::describe() const { return io_->describe() + " node " + std::to_string(node_); }

std::size_t CanTransport::max_chunk_payload() const { return can::kMaxChunkPayload; }

TransportCounters CanTransport::counters() const {
  TransportCounters c = counters_;
  c.bad_replies += io_->garbage();
  return c;
}

void CanTransport::ensure_open() {
  if (io_->is_open()) return;
  Backoff backoff(options_.reconnect_backoff, options_.reconnect_attempts);
  while (true) {
    try {
      io_->open(std::max(options_.response_timeout, milliseconds{1}));
      break;
    } catch (const TransportError& e) {
      io_->close();
      if (e.kind() != Kind::Unreachable) throw;
      if (!backoff.wait_after_failure())
        throw TransportError(Kind::Unreachable, std::string(e.what()) + " (" + std::to_string(backoff.failures()) +
                                                    " attempt" + (backoff.failures() == 1 ? "" : "s") + ")");
    }
  }
  // A new connection starts mid-stream: forget any half snapshot.
  assembler_ = can::StatusAssembler(node_);
  in_snapshot_ = false;
  if (ever_open_) ++counters_.reconnects;
  ever_open_ = true;
  // Wait for the bus to flow (the controller's periodic status) before talking: a
  // socketcand may pass frames to a new raw-mode client only a moment after its `< ok >`,
  // and a flow control sent in that moment would be lost (a transfer stalled for the
  // whole flow control timeout). A silent bus costs one response timeout here.
  if (auto frame = io_->receive(SteadyClock::now() + options_.response_timeout)) dispatch(*frame);
}

void CanTransport::dispatch(const can::CanFrame& frame) {
  if (frame.id == can::status_id(node_)) {
    const bool was_in_snapshot = in_snapshot_;
    const bool starts_snapshot = frame.len == 8 && frame.data[0] == 0;
    auto r = assembler_.on_frame(frame);
    // Frames of a snapshot that began before we listened are refused once, harmlessly; a
    // snapshot broken in the middle (a lost, repeated or corrupt frame) is a bad reply.
    if (r.error && was_in_snapshot) ++counters_.bad_replies;
    if (r.status) {
      latest_ = std::move(r.status);
      ++generation_;
      in_snapshot_ = false;
    } else {
      in_snapshot_ = starts_snapshot || !r.error;
    }
  } else if (frame.id == can::flow_control_id(node_)) {
    if (segmenter_) segmenter_->on_flow_control(frame, now_micros());
  }
  // Other identifiers (other nodes, our own traffic echoed, unrelated devices) are not ours.
}

void CanTransport::drain() {
  for (int i = 0; i < kMaxDrainFrames; ++i) {
    auto frame = io_->receive(SteadyTime::min());
    if (!frame) return;
    dispatch(*frame);
  }
}

std::optional<protocol::Status> CanTransport::wait_status(SteadyTime deadline, std::uint64_t after_generation,
                                                          const std::function<bool(const protocol::Status&)>& fits) {
  while (true) {
    const std::uint64_t before = generation_;
    auto frame = io_->receive(deadline);
    if (!frame) return std::nullopt;
    dispatch(*frame);
    if (generation_ != before && generation_ > after_generation && latest_ && fits(*latest_)) {
      returned_generation_ = generation_;
      return latest_;
    }
  }
}

// Runs `once` (returns the Status, or an Issue) until it succeeds, reopening the
// connection and resending as the header describes.
template <class Once>
auto CanTransport::run(const std::string& what, Once&& once) {
  int resends = 0;
  while (true) {
    ensure_open();
    ++counters_.requests;
    std::optional<Issue> issue;
    try {
      auto result = once();
      if (std::holds_alternative<Issue>(result)) {
        issue = std::get<Issue>(std::move(result));
      } else {
        return std::get<0>(std::move(result));
      }
    } catch (const TransportError& e) {
      if (e.kind() != Kind::Disconnected && e.kind() != Kind::Timeout) throw;
      io_->close();
      issue = Issue{Kind::Disconnected, e.what()};
    }
    if (issue->kind == Kind::Timeout) ++counters_.timeouts;
    if (issue->kind == Kind::Protocol) ++counters_.bad_replies;
    if (resends >= options_.request_retries)
      throw TransportError(issue->kind, describe() + ": " + what + ": " + issue->message +
                                            (resends ? " (after " + std::to_string(resends) + " resend" +
                                                           (resends == 1 ? "" : "s") + ")"
                                                     : std::string()));
    ++resends;
    ++counters_.retries;
  }
}

protocol::Status CanTransport::read_status() {
  return run("read the status (snapshot on 0x" + [&] {
    char b[8];
    std::snprintf(b, sizeof b, "%X", static_cast<unsigned>(can::status_id(node_)));
    return std::string(b);
  }() + ")",
             [&]() -> std::variant<protocol::Status, Issue> {
               drain();
               // A snapshot that arrived since the last one returned is news: no need to
               // wait up to a status period for the next (the end of a program, an alarm).
               if (latest_ && generation_ > returned_generation_) {
                 returned_generation_ = generation_;
                 return *latest_;
               }
               const auto deadline = SteadyClock::now() + options_.response_timeout;
               if (auto s = wait_status(deadline, generation_, [](const protocol::Status&) { return true; })) return *s;
               return Issue{Kind::Timeout, "no status snapshot within " +
                                               std::to_string(options_.response_timeout.count()) + " ms"};
             });
}

protocol::Status CanTransport::send_command(const protocol::Command& command) {
  const auto frames = can::encode_command_frames(command, node_);
  const std::string what = "command " + std::string(protocol::to_string(command.code)) + " seq " + std::to_string(command.seq);
  return run(what, [&]() -> std::variant<protocol::Status, Issue> {
    drain();
    const std::uint64_t generation = generation_;
    io_->send(frames);
    const auto deadline = SteadyClock::now() + options_.response_timeout;
    if (auto s = wait_status(deadline, generation,
                             [&](const protocol::Status& st) { return st.command_seq == command.seq; }))
      return *s;
    return Issue{Kind::Timeout, "no status showing command seq " + std::to_string(command.seq) + " within " +
                                    std::to_string(options_.response_timeout.count()) + " ms"};
  });
}

protocol::Status CanTransport::send_chunk(const protocol::Chunk& chunk) {
  auto message = can::encode_chunk_message(chunk, can::kMaxChunkPayload);
  if (!message.ok())
    throw InputError(describe() + ": chunk " + std::to_string(chunk.seq) + " (lines from " +
                     std::to_string(chunk.first_line) + ") cannot be sent: " + message.error().message);
  const std::string what = "chunk " + std::to_string(chunk.seq);
  return run(what, [&]() -> std::variant<protocol::Status, Issue> {
    drain();
    // The flow control timeout stays the protocol's 1000 ms whatever the response timeout:
    // it matches the controller's wait for a silent sender (see kResendMargin).
    can::CanSegmenter segmenter(node_);
    if (auto error = segmenter.begin(message.value(), can::chunk_transfer_id(chunk.seq), now_micros()))
      throw InputError(describe() + ": " + what + ": " + error->message);
    segmenter_ = &segmenter;
    struct Unhook {  // the segmenter lives in this scope only, however it is left
      can::CanSegmenter*& hook;
      ~Unhook() { hook = nullptr; }
    } unhook{segmenter_};
    std::vector<can::CanFrame> batch;
    while (true) {
      const can::Micros now = now_micros();
      while (auto frame = segmenter.poll(now)) batch.push_back(*frame);
      if (!batch.empty()) {
        io_->send(batch);
        batch.clear();
      }
      const auto state = segmenter.state();
      if (state == can::CanSegmenter::State::Done || state == can::CanSegmenter::State::Failed) break;
      // Sending: wait out the separation time; awaiting flow control: wake up now and then
      // so poll() can see the flow control timeout.
      const SteadyTime deadline = state == can::CanSegmenter::State::Sending
                                      ? to_steady(segmenter.next_send_time())
                                      : SteadyClock::now() + milliseconds{20};
      if (auto frame = io_->receive(deadline)) dispatch(*frame);
    }
    if (segmenter.state() == can::CanSegmenter::State::Failed) {
      const auto& error = segmenter.error();
      const bool timeout = error && (error->kind == can::TransferErrorKind::Timeout ||
                                     error->kind == can::TransferErrorKind::TooManyWaits);
      if (timeout) {
        // The controller may hold our first frame, its flow control lost: until it gives
        // the transfer up (1000 ms after that frame) it takes the same first frame again
        // for a repeat and stays silent, so let that time pass. And a random pause keeps
        // the resends from falling into step with periodic trouble on the bus.
        auto pause = std::chrono::milliseconds(std::random_device{}() % kResendJitterMs);
        if (segmenter.frames_sent() == 1) pause += kResendMargin;
        const auto until = SteadyClock::now() + pause;
        while (SteadyClock::now() < until)
          if (auto frame = io_->receive(until)) dispatch(*frame);
      }
      return Issue{timeout ? Kind::Timeout : Kind::Protocol,
                   "transfer failed: " + (error ? error->message : std::string("(no reason given)"))};
    }
    const std::uint64_t generation = generation_;
    const auto deadline = SteadyClock::now() + options_.response_timeout;
    if (auto s = wait_status(deadline, generation,
                             [&](const protocol::Status& st) { return st.last_written_chunk == chunk.seq; }))
      return *s;
    return Issue{Kind::Timeout, "no status showing chunk " + std::to_string(chunk.seq) + " written within " +
                                    std::to_string(options_.response_timeout.count()) + " ms (the transfer was lost)"};
  });
}

void CanTransport::send_heartbeat(std::uint16_t counter) {
  const can::CanFrame frame = can::encode_heartbeat_frame(counter, node_);
  run("heartbeat", [&]() -> std::variant<bool, Issue> {
    io_->send(std::span<const can::CanFrame>(&frame, 1));
    return true;
  });
}

}  // namespace hybridctl::drivers
