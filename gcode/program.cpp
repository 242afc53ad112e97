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

/// One UTF-8 encoded character: its code point, 0 when the bytes are not valid UTF-8, and
/// how many bytes it takes. An invalid sequence takes its lead byte and the continuation
/// bytes that follow it before it breaks off, so it reads as one character.
struct Utf8Character {
  char32_t code_point = 0;
  std::size_t length = 1;
};

Utf8Character decode_utf8(std::string_view s, std::size_t at) {
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(s[k]); };
  const unsigned char lead = byte(at);
  std::size_t length = 0;
  char32_t code_point = 0;
  if (lead >= 0xC2 && lead <= 0xDF) {
    length = 2;
    code_point = lead & 0x1F;
  } else if (lead >= 0xE0 && lead <= 0xEF) {
    length = 3;
    code_point = lead & 0x0F;
  } else if (lead >= 0xF0 && lead <= 0xF4) {
    length = 4;
    code_point = lead & 0x07;
  } else {
    return {};
  }
  for (std::size_t k = 1; k < length; ++k) {
    if (at + k >= s.size() || (byte(at + k) & 0xC0) != 0x80) return {0, k};
    code_point = (code_point << 6) | (byte(at + k) & 0x3F);
  }
  constexpr char32_t kShortest[] = {0, 0, 0x80, 0x800, 0x10000};  // below: an overlong encoding
  if (code_point < kShortest[length]) return {0, length};
  return {code_point, length};
}

/// How a comment spells a character outside ASCII: the plan's set operators as the
/// arithmetic they stand for, units as people type them, anything else '?'.
std::string_view ascii_spelling(char32_t c) {
  switch (c) {
    case U'\u222A': return "+";  // ∪: a deposit joins the state
    case U'\u2212': return "-";  // −: a cut takes from it
    case U'\u2013': return "-";  // en dash
    case U'\u2014': return "-";  // em dash
    case U'\u00B2': return "2";  // mm²
    case U'\u00B3': return "3";  // mm³
    case U'\u00B0': return " deg";
    case U'\u00D7': return "x";
    case U'\u00F8': return "dia ";  // ø, a diameter
    case U'\u00B5': return "u";     // µ (micro sign)
    case U'\u03BC': return "u";     // μ (Greek mu)
    case U'\u00B1': return "+/-";
    case U'\u2264': return "<=";
    case U'\u2265': return ">=";
    case U'\u2192': return "->";
    default: return "?";
  }
}

}  // namespace

std::string comment_text(std::string_view s) {
  std::string out;
  out.reserve(s.size());
  for (std::size_t i = 0; i < s.size();) {
    char c = s[i];
    if (static_cast<unsigned char>(c) >= 0x80) {
      const Utf8Character u = decode_utf8(s, i);
      out += ascii_spelling(u.code_point);
      i += u.length;
      continue;
    }
    if (c == '(')
      c = '[';
    else if (c == ')')
      c = ']';
    else if (c == '\n' || c == '\r' || c == '\t')
      c = ' ';
    else if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f)
      c = '?';
    out += c;
    ++i;
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
