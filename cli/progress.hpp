#pragma once
// A progress bar on stderr for long work, shown only when stderr is a terminal.

#include <unistd.h>

#include <cstdio>
#include <string>

namespace hybridctl::cli {

class ProgressBar {
 public:
  explicit ProgressBar(std::string label) : label_(std::move(label)), enabled_(::isatty(STDERR_FILENO) == 1) {}
  ~ProgressBar() { finish(); }

  void update(double fraction) {
    if (!enabled_) return;
    const int percent = int(fraction * 100.0 + 0.5);
    if (percent == last_percent_) return;
    last_percent_ = percent;
    constexpr int kWidth = 30;
    const int filled = percent * kWidth / 100;
    std::fprintf(stderr, "\r%s [%s%s] %3d%%", label_.c_str(), std::string(std::size_t(filled), '#').c_str(),
                 std::string(std::size_t(kWidth - filled), ' ').c_str(), percent);
    std::fflush(stderr);
  }

  void finish() {
    if (enabled_ && last_percent_ >= 0) std::fprintf(stderr, "\n");
    enabled_ = false;
  }

 private:
  std::string label_;
  bool enabled_;
  int last_percent_ = -1;
};

}  // namespace hybridctl::cli
