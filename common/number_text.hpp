#pragma once
// Numbers as text for messages and reports, in the three forms the project prints: the
// shortest ("%g": 0.5, 1e+06), fixed decimals ("%.3f": 0.500), and fixed decimals with
// trailing zeros dropped and -0 as 0 (4 digits: 0.5, 12, -0.0001). G-code words have
// their own writer (gcode::format_number), which follows the dialect.

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

}  // namespace hybridctl
