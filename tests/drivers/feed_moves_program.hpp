#pragma once
// A program of ~28-byte feed moves inside the example machine's travel, for streaming
// tests and benchmarks: `moves` moves after a short preamble, under a `title` comment when
// one is given (a distinct title makes a distinct program identity, so a stream repeated
// with a new title starts from line 1). Header-only.

#include <cstdio>
#include <string>
#include <vector>

#include "protocol/chunk.hpp"

namespace hybridctl::testing {

inline std::vector<std::string> feed_moves_program(int moves, const std::string& title = "") {
  std::string p = title.empty() ? std::string() : "(" + title + ")\n";
  p += "G21 G90 G17\nG54\nT1 M6\nS8000 M3\nG0 X0 Y0 Z20\n";
  char line[64];
  for (int i = 0; i < moves; ++i) {
    // "G1 X12.345 Y23.456 Z20 F1200": about 28 bytes.
    std::snprintf(line, sizeof line, "G1 X%.3f Y%.3f Z20 F1200\n", 10 + (i * 7919LL % 40000) / 1000.0,
                  10 + (i * 104729LL % 20000) / 1000.0);
    p += line;
  }
  p += "M5\nM2\n";
  return protocol::program_lines(p);
}

}  // namespace hybridctl::testing
