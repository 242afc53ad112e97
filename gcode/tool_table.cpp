#include "gcode/tool_table.hpp"

#include <algorithm>
#include <vector>

#include "gcode/post.hpp"

namespace hybridctl::gcode {

namespace {

/// Tool names are free text; a table line must stay one line.
std::string one_line(const std::string& s) {
  std::string out = s;
  for (char& c : out)
    if (c == '\n' || c == '\r') c = ' ';
  return out;
}

}  // namespace

std::string linuxcnc_tool_table(const config::Machine& machine) {
  struct Row {
    int number;
    double diameter;
    std::string name;
  };
  std::vector<Row> rows;
  for (const auto& t : machine.tools) rows.push_back({t.number, t.diameter, one_line(t.name)});
  for (const auto& h : machine.heads)
    rows.push_back({h.tool_number, h.bead.width,
                    "head " + one_line(h.name) + " (" + std::string(config::to_string(h.process)) + ")"});
  std::sort(rows.begin(), rows.end(), [](const Row& a, const Row& b) { return a.number < b.number; });
  std::string out;
  for (const Row& r : rows) {
    const std::string n = std::to_string(r.number);
    out += "T" + n + " P" + n + " D" + format_number(r.diameter) + " Z0 ;" + r.name + "\n";
  }
  return out;
}

}  // namespace hybridctl::gcode
