#pragma once
// What a sanitizer printed in a child process's output. In the sanitizer build
// (HYBRIDCTL_SANITIZE, docs/hardening.md) the hybridctl processes the tests start are
// sanitized too; a report ends them with SIGABRT, but some of them are ended by the test
// itself (SIGTERM) or their exit status is not ours to see (started through the shell
// with `&`), so the helpers that read their stderr also look for a report there.

#include <algorithm>
#include <array>
#include <string>
#include <string_view>

namespace hybridctl::test {

/// The sanitizer report in `output` from its first line on, or "" when there is none
/// (AddressSanitizer, LeakSanitizer, UndefinedBehaviorSanitizer's "FILE:LINE:COL:
/// runtime error:").
inline std::string sanitizer_report(std::string_view output) {
  constexpr std::array<std::string_view, 3> kMarkers = {"ERROR: AddressSanitizer", "ERROR: LeakSanitizer", ": runtime error: "};
  std::size_t first = std::string_view::npos;
  for (const auto marker : kMarkers) first = std::min(first, output.find(marker));
  if (first == std::string_view::npos) return {};
  const std::size_t line_start = output.rfind('\n', first);
  return std::string(output.substr(line_start == std::string_view::npos ? 0 : line_start + 1));
}

}  // namespace hybridctl::test
