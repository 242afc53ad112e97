#include "sim/wire/fault_injection.hpp"

#include <charconv>

namespace hybridctl::sim::wire {

std::string parse_line_list(const std::string& text, std::vector<std::uint32_t>& out) {
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = text.find(',', start);
    const std::string item = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    std::uint32_t value = 0;
    const auto [end, ec] = std::from_chars(item.data(), item.data() + item.size(), value);
    if (item.empty() || ec != std::errc() || end != item.data() + item.size() || value == 0) {
      return "'" + text + "': expected a line count (a positive integer) or a comma-separated list of them";
    }
    out.push_back(value);
    if (comma == std::string::npos) return {};
    start = comma + 1;
  }
}

}  // namespace hybridctl::sim::wire
