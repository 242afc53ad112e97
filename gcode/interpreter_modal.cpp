// The steps of a block other than its motion: G codes sorted into modal groups, M codes
// given their roles, units, F S T, tool change, spindle, coolant, outputs, dwell, plane,
// length offset, work offset, distance modes, the check for unused words, and the stops.
// Interpreter::run (interpreter.cpp) calls them in its documented order.
#include <string_view>
#include <utility>

#include "gcode/interpreter_steps.hpp"

namespace hybridctl::gcode {

namespace {

using detail::bit;
using detail::fmt;
using detail::number_word;

constexpr double kMmPerInch = 25.4;

const char* const kKnownG =
    "G0, G1, G2, G3, G4, G17, G18, G19, G20, G21, G40, G43, G49, G53, G54..G59, G61, "
    "G61.1, G64, G80, G90, G90.1, G91, G91.1, G94";

/// A stop's operator message: the line's comment or the preceding comment-only line's,
/// without LinuxCNC's "MSG," prefix.
std::string_view stop_message(std::string_view message) {
  if (message.size() >= 4 && (message.substr(0, 4) == "MSG," || message.substr(0, 4) == "msg,")) {
    message.remove_prefix(4);
    while (!message.empty() && message.front() == ' ') message.remove_prefix(1);
  }
  return message;
}

}  // namespace

Event& BlockExecution::event(EventKind kind, int column) {
  Event& e = in_.result_.events.emplace_back();
  e.line = b_.line;
  e.column = column;
  e.kind = kind;
  return e;
}

void BlockExecution::refuse_words_after_end() const {
  if (s_.ended)
    fail(b_.g_count   ? b_.g[0].column
         : b_.m_count ? b_.m[0].column
                      : 1,
         "found words after the program end; expected nothing but comments or '%' after M2/M30");
}

void BlockExecution::group_g_codes() {
  // G codes as tenths (G90.1 is 901) and their modal groups.
  static constexpr std::pair<int, GGroup> kMembers[] = {
      {0, kMotion},    {10, kMotion},   {20, kMotion},      {30, kMotion},       {800, kMotion},   {170, kPlane},
      {180, kPlane},   {190, kPlane},   {900, kDistance},   {910, kDistance},    {901, kArcDistance},
      {911, kArcDistance},              {940, kFeedMode},   {200, kUnits},       {210, kUnits},    {400, kCutter},
      {430, kLength},  {490, kLength},  {540, kCoords},     {550, kCoords},      {560, kCoords},   {570, kCoords},
      {580, kCoords},  {590, kCoords},  {610, kPath},       {611, kPath},        {640, kPath},     {40, kDwell},
      {530, kMachineCoords}};
  static constexpr const char* kNames[kGGroups] = {
      "motion",      "plane",        "distance mode", "arc distance mode", "feed mode", "units", "cutter compensation",
      "tool length offset", "work offset", "path control", "non-modal", "non-modal"};
  for (int i = 0; i < b_.g_count; ++i) {
    const Code c = b_.g[i];
    int group = -1;
    for (const auto& [code, member_of] : kMembers)
      if (code == c.value) group = member_of;
    if (c.value == 930) fail(c.column, "found G93: inverse time feed is not supported; expected G94 (units per minute)");
    if (c.value == 410 || c.value == 420)
      fail(c.column, "found " + g_code_name(c.value) +
                         ": cutter radius compensation is not supported; expected toolpaths of the tool centre "
                         "(G40)");
    if (group < 0)
      fail(c.column, "found " + g_code_name(c.value) + ", an unknown or unsupported G code; expected one of " + kKnownG);
    Slot& slot = g_[static_cast<std::size_t>(group)];
    if (slot.code >= 0)
      fail(c.column, "found " + g_code_name(c.value) + " after " + g_code_name(slot.code) +
                         " on one line: two codes of the " + kNames[group] + " group; expected at most one");
    slot = {c.value, c.column};
  }
  if (g_[kDwell].code >= 0 && g_[kMotion].code >= 0)
    fail(g_[kDwell].column,
         "found G4 with " + g_code_name(g_[kMotion].code) + "; expected G4 on a line without motion codes");
}

// A head's code first: M62..M65-style codes match on P; a code that is also a spindle or
// coolant code (e.g. M3 for a wire-arc torch) only while that head is active.
int BlockExecution::find_head_code(int m, int tool_after_change) const {
  for (std::size_t k = 0; k < in_.head_codes_.size(); ++k) {
    const Interpreter::HeadCode& hc = in_.head_codes_[k];
    if (hc.m != m) continue;
    if (hc.p >= 0 && !(b_.has('P') && b_.value('P') == hc.p)) continue;
    const Role role = in_.role_of(m);
    if (role != Role::None && tool_after_change != in_.machine_.heads[static_cast<std::size_t>(hc.head)].tool_number)
      continue;
    return static_cast<int>(k);
  }
  return -1;
}

// Each M code has one role; one code per group and line.
void BlockExecution::classify_m_codes() {
  enum Group { kStop, kToolChange, kSpindle, kCoolant, kIo, kGroups };
  std::array<int, kGroups> group_column{};
  int tool_after_change = s_.tool;
  for (int i = 0; i < b_.m_count; ++i)
    if (in_.role_of(b_.m[i].value) == Role::ToolChange)
      // (a T that is no tool number is refused by select_tool, with its column)
      tool_after_change = !b_.has('T') ? s_.selected_tool : number_word(b_.value('T')) ? int(b_.value('T')) : -1;
  for (int i = 0; i < b_.m_count; ++i) {
    const Code c = b_.m[i];
    MAction a;
    a.column = c.column;
    a.m = c.value;
    a.head_code = find_head_code(c.value, tool_after_change);
    Group group = kIo;
    if (a.head_code >= 0) {
      if (in_.head_codes_[static_cast<std::size_t>(a.head_code)].p >= 0) used_ |= bit('P');
    } else {
      a.role = in_.role_of(c.value);
      switch (a.role) {
        case Role::Stop:
        case Role::OptionalStop:
        case Role::End: group = kStop; break;
        case Role::ToolChange: group = kToolChange; break;
        case Role::SpindleCw:
        case Role::SpindleCcw:
        case Role::SpindleStop: group = kSpindle; break;
        case Role::CoolantOn:
        case Role::CoolantOff: group = kCoolant; break;
        case Role::None:
          if ((c.value >= 62 && c.value <= 65) || c.value == 67 || c.value == 68) {
            a.io = c.value;
          } else {
            fail(c.column, "found " + m_code_name(c.value) +
                               ", an unknown M code; expected M0, M1, M2, M3, M4, M5, M6, M7, M8, M9, M30, "
                               "M62..M65, M67, M68 or one of the machine's codes (gcode.m_codes, "
                               "heads[].codes)");
          }
          break;
      }
    }
    if (group_column[group] != 0)
      fail(c.column, "found " + m_code_name(c.value) + " and another M code of the same group (column " +
                         std::to_string(group_column[group]) + ") on one line; expected at most one");
    group_column[group] = c.column;
    actions_[static_cast<std::size_t>(action_count_++)] = a;
  }
}

// Units first: they apply to every number on the line.
void BlockExecution::set_units() {
  if (g_[kUnits].code >= 0) s_.inches = g_[kUnits].code == 200;
  unit_ = s_.inches ? kMmPerInch : 1.0;
}

void BlockExecution::set_feed() {
  if (!b_.has('F')) return;
  const double f = b_.value('F');
  if (f < 0) fail(b_.column('F'), "found F" + fmt(f) + "; expected a feed rate of 0 or more");
  s_.feed = f * unit_;
  used_ |= bit('F');
}

void BlockExecution::set_spindle_speed() {
  if (!b_.has('S')) return;
  const double v = b_.value('S');
  if (v < 0) fail(b_.column('S'), "found S" + fmt(v) + "; expected a spindle speed of 0 or more");
  s_.spindle_speed = v;
  used_ |= bit('S');
}

void BlockExecution::select_tool() {
  if (!b_.has('T')) return;
  const double t = b_.value('T');
  if (!number_word(t))
    fail(b_.column('T'), "found T" + fmt(t) + "; expected a tool number, a whole number from 0 to 99999");
  s_.selected_tool = static_cast<int>(t);
  used_ |= bit('T');
}

void BlockExecution::change_tool() {
  for (int i = 0; i < action_count_; ++i) {
    const MAction& a = actions_[static_cast<std::size_t>(i)];
    if (a.role != Role::ToolChange) continue;
    s_.tool = s_.selected_tool;
    s_.spindle = SpindleState::Off;  // as LinuxCNC's M6 does
    event(EventKind::ToolChange, a.column).tool = s_.tool;
  }
}

void BlockExecution::switch_spindle() {
  for (int i = 0; i < action_count_; ++i) {
    const MAction& a = actions_[static_cast<std::size_t>(i)];
    if (a.head_code >= 0) continue;
    if (a.role == Role::SpindleCw || a.role == Role::SpindleCcw) {
      s_.spindle = a.role == Role::SpindleCw ? SpindleState::Cw : SpindleState::Ccw;
      event(EventKind::SpindleStart, a.column).value = s_.spindle_speed;
    } else if (a.role == Role::SpindleStop) {
      s_.spindle = SpindleState::Off;
      event(EventKind::SpindleStop, a.column);
    }
  }
}

void BlockExecution::switch_coolant() {
  for (int i = 0; i < action_count_; ++i) {
    const MAction& a = actions_[static_cast<std::size_t>(i)];
    if (a.head_code >= 0) continue;
    if (a.role == Role::CoolantOn) {
      s_.coolant = true;
      event(EventKind::CoolantOn, a.column);
    } else if (a.role == Role::CoolantOff) {
      s_.coolant = false;
      event(EventKind::CoolantOff, a.column);
    }
  }
}

void BlockExecution::switch_outputs() {
  for (int i = 0; i < action_count_; ++i) {
    const MAction& a = actions_[static_cast<std::size_t>(i)];
    if (a.head_code >= 0)
      switch_head(a);
    else if (a.io >= 62 && a.io <= 65)
      set_digital_output(a);
    else if (a.io == 67 || a.io == 68)
      set_analog_output(a);
  }
}

void BlockExecution::switch_head(const MAction& a) {
  const Interpreter::HeadCode& hc = in_.head_codes_[static_cast<std::size_t>(a.head_code)];
  if (hc.on)
    s_.deposition |= 1u << hc.head;
  else
    s_.deposition &= ~(1u << hc.head);
  Event& e = event(hc.on ? EventKind::DepositionOn : EventKind::DepositionOff, a.column);
  e.index = hc.head;
  e.tool = in_.machine_.heads[static_cast<std::size_t>(hc.head)].tool_number;
  if (b_.has('E')) used_ |= bit('E');
  if (b_.has('Q')) used_ |= bit('Q');
}

void BlockExecution::set_digital_output(const MAction& a) {
  if (!b_.has('P'))
    fail(a.column, "found " + m_code_name(a.io) + " with no P word; expected the output number, e.g. " +
                       m_code_name(a.io) + " P0");
  const double p = b_.value('P');
  if (!number_word(p))
    fail(b_.column('P'), "found P" + fmt(p) + " with " + m_code_name(a.io) +
                             "; expected an output number, a whole number from 0 to 99999");
  used_ |= bit('P');
  Event& e = event(EventKind::DigitalOutput, a.column);
  e.index = static_cast<int>(p);
  e.value = (a.io == 62 || a.io == 64) ? 1.0 : 0.0;
}

void BlockExecution::set_analog_output(const MAction& a) {
  if (!b_.has('E') || !b_.has('Q'))
    fail(a.column, "found " + m_code_name(a.io) + " without " + (b_.has('E') ? "Q" : "E") +
                       "; expected the output number E and its value Q, e.g. " + m_code_name(a.io) + " E0 Q800");
  const double e_number = b_.value('E');
  if (!number_word(e_number))
    fail(b_.column('E'),
         "found E" + fmt(e_number) + "; expected an analog output number, a whole number from 0 to 99999");
  used_ |= bit('E') | bit('Q');
  Event& e = event(EventKind::AnalogOutput, a.column);
  e.index = static_cast<int>(e_number);
  e.value = b_.value('Q');
}

// RS274NGC G4 P<seconds>; Fanuc G4 X<seconds> or G4 P<milliseconds>.
void BlockExecution::dwell() {
  const Slot& dwell = g_[kDwell];
  if (dwell.code < 0) return;
  const bool fanuc = in_.machine_.gcode.dialect == config::Dialect::Fanuc;
  char letter = 'P';
  if (fanuc && b_.has('X')) letter = 'X';
  if (!b_.has(letter))
    fail(dwell.column, fanuc ? "found G4 with no X or P word; expected the dwell as X<seconds> or P<milliseconds>, "
                               "e.g. G4 X0.5"
                             : "found G4 with no P word; expected the dwell time in seconds, e.g. G4 P0.5");
  const double value = b_.value(letter);
  if (value < 0)
    fail(b_.column(letter), "found " + std::string(1, letter) + fmt(value) + " with G4; expected a dwell of 0 or more");
  dwell_letters_ = bit(letter);
  used_ |= dwell_letters_;
  event(EventKind::Dwell, dwell.column).value = fanuc && letter == 'P' ? value / 1000.0 : value;
}

void BlockExecution::set_plane() {
  const int code = g_[kPlane].code;
  if (code >= 0) s_.plane = code == 170 ? Plane::XY : code == 180 ? Plane::ZX : Plane::YZ;
}

void BlockExecution::set_length_offset() {
  const Slot& length = g_[kLength];
  if (length.code == 430) {
    if (!b_.has('H'))
      fail(length.column, "found G43 with no H word; expected the tool length offset number, e.g. G43 H1");
    const double h = b_.value('H');
    if (!number_word(h))
      fail(b_.column('H'), "found H" + fmt(h) + "; expected a tool number, a whole number from 0 to 99999");
    s_.tool_length_offset = static_cast<int>(h);
    used_ |= bit('H');
  } else if (length.code == 490) {
    s_.tool_length_offset = 0;
  }
}

void BlockExecution::set_work_offset() {
  const Slot& coords = g_[kCoords];
  if (coords.code < 0) return;
  const config::Machine& machine = in_.machine_;
  const int offset = coords.code / 10;
  const config::Setup* setup = machine.find_setup_by_work_offset(offset);
  if (!setup) {
    std::string known;
    for (const auto& st : machine.setups)
      known += (known.empty() ? "" : ", ") + std::string("G") + std::to_string(st.work_offset) + " (" + st.name + ")";
    fail(coords.column, "found G" + std::to_string(offset) + ", a work offset no setup of machine '" + machine.name +
                            "' uses; expected one of " + known);
  }
  s_.work_offset = offset;
  s_.offset = {setup->work_origin[0], setup->work_origin[1], setup->work_origin[2]};
  event(EventKind::WorkOffset, coords.column).index = offset;
}

void BlockExecution::set_distance_modes() {
  if (g_[kDistance].code >= 0) s_.absolute = g_[kDistance].code == 900;
  if (g_[kArcDistance].code >= 0) s_.arc_absolute = g_[kArcDistance].code == 901;
}

void BlockExecution::refuse_unused_words() const {
  const std::uint32_t always = bit('F') | bit('S') | bit('T');
  const std::uint32_t unused = b_.letters & ~used_ & ~always;
  if (unused == 0) return;
  for (int k = 0; k < 26; ++k) {
    if (!((unused >> k) & 1u)) continue;
    const char L = static_cast<char>('A' + k);
    std::string why;
    switch (L) {
      case 'I':
      case 'J':
      case 'K':
      case 'R': why = "expected it only with G2 or G3"; break;
      case 'P': why = "expected it only with G4, M62..M65 or a head's code"; break;
      case 'E':
      case 'Q': why = "expected it only with M67 or M68"; break;
      case 'H': why = "expected it only with G43"; break;
      default: why = "hybridctl does not use " + std::string(1, L) + " words"; break;
    }
    fail(b_.column(L), "found " + std::string(1, L) + fmt(b_.value(L)) + " with nothing on the line to use it; " + why);
  }
}

// Stops and program end come after the motion.
void BlockExecution::stop_or_end() {
  for (int i = 0; i < action_count_; ++i) {
    const MAction& a = actions_[static_cast<std::size_t>(i)];
    if (a.head_code >= 0) continue;
    if (a.role == Role::Stop || a.role == Role::OptionalStop) {
      Event& e = event(a.role == Role::Stop ? EventKind::ProgramStop : EventKind::OptionalStop, a.column);
      e.after_motion = true;
      e.message.assign(stop_message(!b_.comment.empty() ? b_.comment : std::string_view(in_.pending_comment_)));
    } else if (a.role == Role::End) {
      event(EventKind::ProgramEnd, a.column).after_motion = true;
      s_.ended = true;
      s_.spindle = SpindleState::Off;
      s_.coolant = false;
      s_.absolute = true;
      s_.plane = Plane::XY;
    }
  }
}

}  // namespace hybridctl::gcode
