#include "gcode/program.hpp"

#include <charconv>

#include "gcode/parser.hpp"

namespace hybridctl::gcode {

namespace {

std::string_view to_string(ActionMode m) { return m == ActionMode::Additive ? "additive" : "subtractive"; }
std::string_view to_string(Process p) { return p == Process::Deposition ? "deposition" : "milling"; }

/// Consumes `prefix` from the front of `s`.
bool take(std::string_view& s, std::string_view prefix) {
  if (s.substr(0, prefix.size()) != prefix) return false;
  s.remove_prefix(prefix.size());
  return true;
}

/// The comment that makes up the whole line, after an optional block number "N123 ".
std::optional<std::string_view> whole_line_comment(std::string_view line) {
  if (!line.empty() && line[0] == 'N') {
    std::size_t i = 1;
    while (i < line.size() && line[i] >= '0' && line[i] <= '9') ++i;
    if (i == 1 || i >= line.size() || line[i] != ' ') return std::nullopt;
    line.remove_prefix(i + 1);
  }
  if (line.size() < 2 || line.front() != '(' || line.back() != ')') return std::nullopt;
  return line.substr(1, line.size() - 2);
}

/// Our action heading, read back: the inverse of ProgramAction::heading().
std::optional<ProgramAction> parse_heading(std::string_view body) {
  ProgramAction a;
  std::string_view s = body;
  if (!take(s, "action ")) return std::nullopt;
  const auto [end, error] = std::from_chars(s.data(), s.data() + s.size(), a.number);
  if (error != std::errc() || a.number < 0) return std::nullopt;
  s.remove_prefix(static_cast<std::size_t>(end - s.data()));
  if (!take(s, ": primitive ")) return std::nullopt;
  const std::size_t additive = s.find(", additive "), subtractive = s.find(", subtractive ");
  const std::size_t mode_at = std::min(additive, subtractive);
  if (mode_at == std::string_view::npos) return std::nullopt;
  a.primitive = s.substr(0, mode_at);
  s.remove_prefix(mode_at + 2);
  if (take(s, "additive "))
    a.mode = ActionMode::Additive;
  else if (take(s, "subtractive "))
    a.mode = ActionMode::Subtractive;
  else
    return std::nullopt;
  if (take(s, "deposition with "))
    a.process = Process::Deposition;
  else if (take(s, "milling with "))
    a.process = Process::Milling;
  else
    return std::nullopt;
  const std::size_t setup_at = s.rfind(" in setup ");
  if (setup_at == std::string_view::npos) return std::nullopt;
  a.instrument = s.substr(0, setup_at);
  a.setup = s.substr(setup_at + 10);
  // Only what heading() writes, exactly, is ours.
  if (a.heading() != body) return std::nullopt;
  return a;
}

}  // namespace

std::string comment_text(std::string_view s) {
  std::string out;
  out.reserve(s.size());
  for (char c : s) {
    if (c == '(')
      c = '[';
    else if (c == ')')
      c = ']';
    else if (c == '\n' || c == '\r' || c == '\t')
      c = ' ';
    else if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f)
      c = '?';
    out += c;
  }
  return out;
}

std::string ProgramAction::heading() const {
  return "action " + std::to_string(number) + ": primitive " + primitive + ", " + std::string(to_string(mode)) + " " +
         std::string(to_string(process)) + " with " + instrument + " in setup " + setup;
}

std::string PostedProgram::text() const {
  std::size_t size = 0;
  for (const auto& l : lines) size += l.size() + 1;
  std::string out;
  out.reserve(size);
  for (const auto& l : lines) {
    out += l;
    out += '\n';
  }
  return out;
}

const ProgramAction* PostedProgram::action_at(std::uint32_t line) const {
  if (line == 0 || line > origins.size()) return nullptr;
  const auto& action = origins[line - 1].action;
  return action ? &actions[*action] : nullptr;
}

PostedProgram PostedProgram::from_lines(std::vector<std::string> lines) {
  PostedProgram p;
  p.lines = std::move(lines);
  p.origins.resize(p.lines.size());
  for (std::size_t i = 0; i < p.lines.size(); ++i) {
    const auto body = whole_line_comment(p.lines[i]);
    std::optional<ProgramAction> heading = body ? parse_heading(*body) : std::nullopt;
    if (heading) {
      if (!p.actions.empty()) p.actions.back().last_line = static_cast<std::uint32_t>(i);
      heading->first_line = static_cast<std::uint32_t>(i + 1);
      p.actions.push_back(std::move(*heading));
    }
    if (!p.actions.empty()) p.origins[i].action = p.actions.size() - 1;
  }
  if (!p.actions.empty()) p.actions.back().last_line = static_cast<std::uint32_t>(p.lines.size());
  return p;
}

PostedProgram PostedProgram::from_text(std::string_view text) {
  std::vector<std::string> lines;
  for_each_line(text, [&](std::string_view line, int) { lines.emplace_back(line); });
  return from_lines(std::move(lines));
}

}  // namespace hybridctl::gcode
