#include "sim/wire/serve_loop.hpp"

#include <algorithm>
#include <cerrno>
#include <system_error>

#include <signal.h>
#include <time.h>

#include "sim/controller.hpp"

namespace hybridctl::sim::wire {

ServeLoop::ServeLoop(Controller& controller, ServeLoopOptions options)
    : controller_(controller), options_(std::move(options)) {
  auto& lines = options_.reboot_after_lines;
  std::sort(lines.begin(), lines.end());
  lines.erase(std::unique(lines.begin(), lines.end()), lines.end());
}

void ServeLoop::apply_reboot_schedule() {
  const auto& lines = options_.reboot_after_lines;
  if (next_reboot_ >= lines.size()) return;
  const std::size_t executed = controller_.executed_lines().size();
  if (executed < lines[next_reboot_]) return;
  // One reboot even if the clock jumped past several thresholds at once: a controller
  // that just rebooted executes nothing until the host resets the alarm.
  while (next_reboot_ < lines.size() && lines[next_reboot_] <= executed) ++next_reboot_;
  controller_.reboot();
  ++reboots_;
}

ServeExit ServeLoop::run(const std::atomic<bool>& stop) {
  std::vector<pollfd> fds;
  std::vector<std::size_t> counts(endpoints_.size());
  const SteadyTime start = SteadyClock::now();
  SteadyTime last = start;
  // After COMPLETED the loop serves on for a short while so hosts can read the final
  // status (a host polls; an immediate exit would turn its last read into a refused
  // connection).
  constexpr auto kLinger = std::chrono::milliseconds(500);
  SteadyTime completed_at = SteadyTime::max();
  ServeExit result = ServeExit::Stopped;

  bool executing = false;  // the last advance() executed lines
  while (!stop.load(std::memory_order_relaxed)) {
    fds.clear();
    for (std::size_t i = 0; i < endpoints_.size(); ++i) {
      const std::size_t before = fds.size();
      endpoints_[i]->collect(fds);
      counts[i] = fds.size() - before;
    }
    SteadyTime now = SteadyClock::now();
    SteadyTime wake = executing && options_.spin_while_executing ? now : now + options_.max_wait;
    for (const WireEndpoint* e : endpoints_) wake = std::min(wake, e->next_deadline());
    const auto wait = std::max(std::chrono::nanoseconds(0), std::chrono::nanoseconds(wake - now));
    timespec ts{static_cast<time_t>(wait.count() / 1'000'000'000), static_cast<long>(wait.count() % 1'000'000'000)};
    const int rc = ::ppoll(fds.data(), fds.size(), &ts, nullptr);
    if (rc < 0 && errno != EINTR) throw std::system_error(errno, std::generic_category(), "sim serve: poll");

    now = SteadyClock::now();
    const std::size_t executed_before = controller_.executed_lines().size();
    controller_.advance(std::chrono::duration<double>(now - last).count());
    last = now;
    executing = controller_.executed_lines().size() != executed_before;
    apply_reboot_schedule();

    if (rc > 0) {
      std::size_t at = 0;
      for (std::size_t i = 0; i < endpoints_.size(); ++i) {
        endpoints_[i]->service(std::span<const pollfd>(fds.data() + at, counts[i]), now);
        at += counts[i];
      }
    }
    for (WireEndpoint* e : endpoints_) e->tick(now);

    if (options_.exit_when_done) {
      if (completed_at == SteadyTime::max() &&
          controller_.status().state == protocol::ControllerState::Completed) {
        completed_at = now;
      }
      if (completed_at != SteadyTime::max() && now - completed_at >= kLinger) {
        result = ServeExit::Completed;
        break;
      }
    }
  }
  real_seconds_ = std::chrono::duration<double>(SteadyClock::now() - start).count();
  return result;
}

}  // namespace hybridctl::sim::wire
