#pragma once
// The single-threaded event loop of `hybridctl sim serve`: one poll() over every wire
// endpoint's descriptors (Modbus TCP listener and clients, the RTU line, socketcand
// listener and clients, a SocketCAN socket), the controller's clock advanced by the real
// time that passed at every wake-up, and the reboot schedule of the fault injection.
// sim::Controller is not thread-safe; here every call to it happens on this one thread.
//
//   sim::ServeLoop loop(controller, {.exit_when_done = true});
//   loop.add(modbus_tcp);  loop.add(socketcand);
//   loop.run(stop_flag);   // until stop_flag (set by a signal handler) or the program completed

#include <atomic>
#include <chrono>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include <poll.h>

namespace hybridctl::sim {
class Controller;
}

namespace hybridctl::sim::wire {

using SteadyClock = std::chrono::steady_clock;
using SteadyTime = SteadyClock::time_point;

/// A server the loop drives. Every call happens on the loop's thread.
class WireEndpoint {
 public:
  virtual ~WireEndpoint() = default;

  /// Appends the descriptors to wait on (POLLIN, plus POLLOUT while output is pending).
  virtual void collect(std::vector<pollfd>& fds) = 0;
  /// Handles what poll() reported on the descriptors collect() appended, in that order.
  virtual void service(std::span<const pollfd> fds, SteadyTime now) = 0;
  /// Timed work (periodic status, delayed replies, bus pacing, transfer timeouts).
  virtual void tick(SteadyTime /*now*/) {}
  /// The earliest time tick() has work to do; SteadyTime::max() when none.
  virtual SteadyTime next_deadline() const { return SteadyTime::max(); }
};

struct ServeLoopOptions {
  /// Longest sleep in poll(): how often the controller's clock advances when nothing
  /// happens on the wire (1-5 ms keeps virtual time smooth at time scale 1).
  std::chrono::microseconds max_wait{2000};
  /// Return once the controller reports COMPLETED (after every endpoint ticked once more,
  /// so the hosts see the final status).
  bool exit_when_done = false;
  /// Reboot the controller once it executed this many lines (each value once, ascending).
  /// The reboot comes after the advance() that crossed the count: for an exact line, give
  /// the controller max_lines_per_advance = 1 (and spin_while_executing at time scale 0).
  std::vector<std::uint32_t> reboot_after_lines;
  /// Do not sleep while the controller is executing lines (time scale 0: as fast as
  /// possible, even with a small max_lines_per_advance). The loop still sleeps while the
  /// controller waits for chunks or commands.
  bool spin_while_executing = false;
};

enum class ServeExit { Stopped, Completed };

class ServeLoop {
 public:
  ServeLoop(Controller& controller, ServeLoopOptions options);

  /// The endpoint must outlive run().
  void add(WireEndpoint& endpoint) { endpoints_.push_back(&endpoint); }

  /// Serves until `stop` becomes true (a signal handler sets it; poll() is interrupted by
  /// the signal, so the reaction is immediate) or, with exit_when_done, the program
  /// completed. Throws std::system_error when poll() itself fails.
  ServeExit run(const std::atomic<bool>& stop);

  std::uint32_t reboots_injected() const { return reboots_; }
  /// Wall time spent in run(), seconds.
  double real_seconds() const { return real_seconds_; }

 private:
  void apply_reboot_schedule();

  Controller& controller_;
  ServeLoopOptions options_;
  std::vector<WireEndpoint*> endpoints_;
  std::size_t next_reboot_ = 0;
  std::uint32_t reboots_ = 0;
  double real_seconds_ = 0;
};

}  // namespace hybridctl::sim::wire
