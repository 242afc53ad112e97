#include "gcode/restart.hpp"

#include <cstdio>
#include <string_view>

#include "common/number_text.hpp"
#include "common/error.hpp"
#include "gcode/interpreter.hpp"

namespace hybridctl::gcode {
namespace {

// Enough digits for a micrometre (or a tenth of a thou), no trailing zeros.
std::string number(double v) { return trimmed_number(v, 4); }

// The lines that bring a freshly booted controller to `s`, the modal state after the
// restart line's predecessor. Motion last: retract to the top of Z (machine frame), set
// tool and spindle up there, go over the position, feed down to it, switch deposition on.
std::vector<std::string> preamble(const ModalState& s, const config::Machine& m, std::uint32_t from_line) {
  const double unit = s.inches ? 25.4 : 1.0;
  const Vec3 p = s.work_position();
  std::vector<std::string> out;
  out.push_back("(restart at line " + std::to_string(from_line) + ": modal state after line " + std::to_string(from_line - 1) +
                " restored)");
  const char* plane = s.plane == Plane::XY ? "G17" : s.plane == Plane::ZX ? "G18" : "G19";
  out.push_back(std::string(s.inches ? "G20" : "G21") + " G90 " + plane + " G94 G40 G49 G80");
  out.push_back("G" + std::to_string(s.work_offset));
  out.push_back("G53 G0 Z" + number(m.envelope.z.travel.max / unit));
  if (s.tool != 0) out.push_back("T" + std::to_string(s.tool) + " " + m.gcode.m_codes.tool_change);
  if (s.selected_tool != s.tool && s.selected_tool != 0) out.push_back("T" + std::to_string(s.selected_tool));
  if (s.tool_length_offset != 0) out.push_back("G43 H" + std::to_string(s.tool_length_offset));
  if (s.spindle != SpindleState::Off)
    out.push_back("S" + number(s.spindle_speed) + " " +
                  (s.spindle == SpindleState::Cw ? m.gcode.m_codes.spindle_cw : m.gcode.m_codes.spindle_ccw));
  if (s.coolant) out.push_back(m.gcode.m_codes.coolant_on);
  if (const config::AdditiveHead* head = m.find_head_by_tool(s.tool); head && head->codes.power_template) {
    std::string code = *head->codes.power_template;
    code.replace(code.find("{power}"), 7, number(head->codes.power));
    out.push_back(code);
  }
  out.push_back("G0 X" + number(p.x / unit) + " Y" + number(p.y / unit));
  // Down at the program's feed: the stock below may be uncut on a controller that lost
  // the cuts' record, and a rapid into it is an alarm.
  out.push_back("G1 Z" + number(p.z / unit) + " F" + number(s.feed > 0 ? s.feed / unit : 100.0 / unit));
  for (std::size_t i = 0; i < m.heads.size() && i < 32; ++i)
    if (s.deposition & (1u << i)) out.push_back(m.heads[i].codes.on);
  // The motion mode the next line may rely on (a bare "X.. Y.." continues it).
  if (s.motion_active && s.motion == MotionKind::Rapid) out.push_back("G0 Z" + number(p.z / unit));
  if (!s.absolute) out.push_back("G91");
  return out;
}

}  // namespace

RestartProgram restart_program(std::span<const std::string> lines, std::uint32_t from_line, const config::Machine& machine) {
  if (from_line < 1 || from_line > lines.size())
    throw InputError("--from-line " + std::to_string(from_line) + ": the program has " + std::to_string(lines.size()) +
                     " lines; expected 1.." + std::to_string(lines.size()));
  Interpreter interpreter(machine, "<program>");
  for (std::uint32_t n = 1; n < from_line; ++n) interpreter.execute_line(lines[n - 1], int(n));
  RestartProgram r;
  r.from_line = from_line;
  r.lines = preamble(interpreter.state(), machine, from_line);
  r.preamble_lines = std::uint32_t(r.lines.size());
  r.lines.insert(r.lines.end(), lines.begin() + (from_line - 1), lines.end());
  return r;
}

}  // namespace hybridctl::gcode
