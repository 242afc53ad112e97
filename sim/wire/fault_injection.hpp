#pragma once
// Fault injection for `hybridctl sim serve`: the wire servers (sim/wire/modbus_server.hpp,
// sim/wire/socketcand_server.hpp) ask a FaultInjector before answering, so a host's retry,
// reconnect and resume logic meets the faults a real line and controller produce, in a
// reproducible order. Every kind counts its own stream of events: by default the k-th
// event of a kind is hit when k is a multiple of its period; with a seed, each event is hit
// with probability 1/period and delays are random, drawn from that seed (a soak run's
// faults, still the same every time for the same seed and traffic). docs/simulator.md
// lists which events each transport counts.

#include <chrono>
#include <cstdint>
#include <optional>
#include <random>
#include <string>
#include <vector>

namespace hybridctl::sim::wire {

struct FaultOptions {
  std::uint32_t drop_every = 0;       ///< close the client's connection at every N-th request (RTU: no reply); 0: never
  std::uint32_t delay_ms = 0;         ///< every reply leaves this long after its request arrived
  std::uint32_t corrupt_every = 0;    ///< every N-th reply goes out with a damaged byte; 0: never
  std::uint32_t exception_every = 0;  ///< every N-th request answered "busy" (Modbus exception 6) unprocessed; 0: never
  std::vector<std::uint32_t> reboot_after_lines;  ///< reboot the controller once it executed L lines (each L once)
  std::uint32_t alarm_at_line = 0;    ///< EMERGENCY_STOP when this program line is about to execute (the controller does it)
  std::uint32_t hold_at_line = 0;     ///< feed hold at the machine when this line is about to execute (cycle start: RESUME)
  /// Random faults: each event of a kind with period N is hit with probability 1/N, each
  /// reply held back a uniform 0..delay_ms ms, all drawn from this seed. Unset: periodic.
  std::optional<std::uint64_t> seed;

  bool any() const {
    return drop_every || delay_ms || corrupt_every || exception_every || !reboot_after_lines.empty() || alarm_at_line ||
           hold_at_line;
  }
};

/// What was injected, for the run report.
struct FaultCounters {
  std::uint64_t dropped = 0;     ///< connections closed (or RTU requests left unanswered)
  std::uint64_t delayed = 0;     ///< replies held back by delay_ms
  std::uint64_t corrupted = 0;   ///< replies sent damaged
  std::uint64_t busy = 0;        ///< requests refused as busy (Modbus exception 6, CAN flow control overflow/abort)
};

/// One transport's fault schedule. Not thread-safe (the serve loop is one thread).
class FaultInjector {
 public:
  explicit FaultInjector(const FaultOptions& options = {}) : options_(options), random_(options.seed.value_or(0)) {}

  /// A request arrived: true when this one is to be dropped (its connection closed).
  bool drop_request() { return hit(options_.drop_every, requests_for_drop_, counters_.dropped); }
  /// true when this request is to be refused as busy without processing it.
  bool refuse_request() { return hit(options_.exception_every, requests_for_busy_, counters_.busy); }
  /// A reply is about to leave: true when it is to be damaged.
  bool corrupt_reply() { return hit(options_.corrupt_every, replies_, counters_.corrupted); }
  /// How long to hold a reply back (counts it when non-zero).
  std::chrono::milliseconds reply_delay() {
    std::uint32_t ms = options_.delay_ms;
    if (ms && options_.seed) ms = static_cast<std::uint32_t>(random_() % (std::uint64_t{ms} + 1));
    if (ms) ++counters_.delayed;
    return std::chrono::milliseconds(ms);
  }
  bool delays() const { return options_.delay_ms != 0; }
  bool corrupts() const { return options_.corrupt_every != 0; }

  const FaultCounters& counters() const { return counters_; }
  const FaultOptions& options() const { return options_; }

 private:
  bool hit(std::uint32_t every, std::uint64_t& events, std::uint64_t& injected) {
    if (every == 0) return false;
    ++events;
    const bool strikes = options_.seed ? random_() % every == 0 : events % every == 0;
    if (!strikes) return false;
    ++injected;
    return true;
  }

  FaultOptions options_;
  std::mt19937_64 random_;
  std::uint64_t requests_for_drop_ = 0;
  std::uint64_t requests_for_busy_ = 0;
  std::uint64_t replies_ = 0;
  FaultCounters counters_;
};

/// Parses "L" or "L1,L2,..." (positive integers) into `out`; returns an error message or "".
std::string parse_line_list(const std::string& text, std::vector<std::uint32_t>& out);

}  // namespace hybridctl::sim::wire
