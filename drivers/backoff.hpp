#pragma once
// The reconnect schedule every transport backend follows (docs/drivers.md, "Reconnect
// policy"): wait `first` after the first failed attempt, double the wait after each further
// failure, never more than kMaxBackoff; give up after `attempts` attempts.

#include <algorithm>
#include <chrono>
#include <thread>

namespace hybridctl::drivers {

inline constexpr std::chrono::milliseconds kMaxBackoff{2000};

class Backoff {
 public:
  Backoff(std::chrono::milliseconds first, int attempts)
      : next_(std::max(first, std::chrono::milliseconds{1})), attempts_(std::max(attempts, 1)) {}

  /// Call after a failed attempt: false when no attempt is left, else sleeps the current
  /// wait, doubles it (up to kMaxBackoff) and returns true.
  bool wait_after_failure() {
    if (++failures_ >= attempts_) return false;
    std::this_thread::sleep_for(next_);
    next_ = std::min(next_ * 2, kMaxBackoff);
    return true;
  }
  int failures() const { return failures_; }

 private:
  std::chrono::milliseconds next_;
  int attempts_;
  int failures_ = 0;
};

}  // namespace hybridctl::drivers
