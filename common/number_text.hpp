#pragma once
// Numbers as text for messages and reports, in the three forms the project prints: the
// shortest ("%g": 0.5, 1e+06), fixed decimals ("%.3f": 0.500), and fixed decimals with
// trailing zeros dropped and -0 as 0 (4 digits: 0.5, 12, -0.0001). G-code words have
// their own writer (gcode::format_number), which follows the dialect.

#include <cmath>
#include <cstdio>
#include <string>

namespace hybridctl {

inline std::string shortest_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

inline std::string fixed_number(double v, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

inline std::string trimmed_number(double v, int digits) {
  std::string s = fixed_number(v, digits);
  if (s.find('.') != std::string::npos) {
    while (s.back() == '0') s.pop_back();
    if (s.back() == '.') s.pop_back();
  }
  return s == "-0" ? "0" : s;
}

/// A duration as every cycle time is printed: "12.4 s", "3 min 12.4 s", "1 h 02 min 03 s".
inline std::string format_duration(double seconds) {
  char buf[64];
  if (seconds < 60) {
    std::snprintf(buf, sizeof buf, "%.1f s", seconds);
  } else if (seconds < 3600) {
    const int minutes = static_cast<int>(seconds / 60);
    std::snprintf(buf, sizeof buf, "%d min %04.1f s", minutes, seconds - 60.0 * minutes);
  } else {
    const long total = std::lround(seconds);
    std::snprintf(buf, sizeof buf, "%ld h %02ld min %02ld s", total / 3600, (total / 60) % 60, total % 60);
  }
  return buf;
}

}  // namespace hybridctl
