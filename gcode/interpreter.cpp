#include "gcode/interpreter.hpp"

#include <cmath>
#include <cstdio>

namespace hybridctl::gcode {

namespace {

constexpr double kMmPerInch = 25.4;
/// LinuxCNC's RADIUS_TOLERANCE_MM: an R arc may miss reaching its end by this much, and
/// centre-format radii below it are zero.
constexpr double kRadiusTolerance = 0.00127;
/// Two in-plane points closer than this are the same point (a full circle).
constexpr double kSamePoint = 1e-9;
constexpr int kMaxHeads = 32;
/// T, H, P (output) and E (analog output) numbers are whole numbers from 0 to this.
constexpr double kMaxNumberWord = 99999;

/// Whether a T, H, P or E value is such a number (and so fits an int).
bool number_word(double v) { return v >= 0 && v <= kMaxNumberWord && v == std::nearbyint(v); }

std::string fmt(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4f", v);
  std::string s = buf;
  while (!s.empty() && s.back() == '0') s.pop_back();
  if (!s.empty() && s.back() == '.') s.pop_back();
  if (s == "-0") s = "0";
  return s;
}

double& at(Vec3& v, int axis) { return axis == 0 ? v.x : axis == 1 ? v.y : v.z; }

/// The in-plane axes (first, second) and the normal of a plane, as 0 = X, 1 = Y, 2 = Z.
struct PlaneAxes {
  int first, second, normal;
  char first_offset, second_offset;  // I J K letters of the in-plane axes
  const char* name;
  const char* axes;
};
PlaneAxes axes_of(Plane p) {
  switch (p) {
    case Plane::XY: return {0, 1, 2, 'I', 'J', "XY", "X or Y"};
    case Plane::ZX: return {2, 0, 1, 'K', 'I', "ZX", "Z or X"};
    case Plane::YZ: return {1, 2, 0, 'J', 'K', "YZ", "Y or Z"};
  }
  return {0, 1, 2, 'I', 'J', "XY", "X or Y"};
}

int m_number(const std::string& code) { return std::atoi(code.c_str() + 1); }

constexpr std::uint32_t bit(char letter) { return 1u << (letter - 'A'); }
constexpr std::uint32_t kAxisLetters = bit('X') | bit('Y') | bit('Z') | bit('A') | bit('B') | bit('C');
constexpr std::uint32_t kArcLetters = bit('I') | bit('J') | bit('K') | bit('R');

const char* const kKnownG =
    "G0, G1, G2, G3, G4, G17, G18, G19, G20, G21, G40, G43, G49, G53, G54..G59, G61, "
    "G61.1, G64, G80, G90, G90.1, G91, G91.1, G94";

}  // namespace

std::string_view to_string(MotionKind k) {
  switch (k) {
    case MotionKind::Rapid: return "rapid";
    case MotionKind::Feed: return "feed";
    case MotionKind::ArcCw: return "arc cw";
    case MotionKind::ArcCcw: return "arc ccw";
  }
  return "?";
}

Interpreter::Interpreter(const config::Machine& machine, std::string file_name, InterpreterOptions options)
    : machine_(machine), parser_(std::move(file_name)), options_(std::move(options)) {
  const config::Envelope& e = machine.envelope;
  state_.position = options_.start.value_or(
      Vec3{0.5 * (e.x.travel.min + e.x.travel.max), 0.5 * (e.y.travel.min + e.y.travel.max), e.z.travel.max});
  if (const config::Setup* s = machine.find_setup_by_work_offset(54))
    state_.offset = {s->work_origin[0], s->work_origin[1], s->work_origin[2]};

  const config::MCodes& c = machine.gcode.m_codes;
  machine_m_codes_ = {{{m_number(c.program_stop), MRole::Stop},
                       {m_number(c.optional_stop), MRole::OptionalStop},
                       {m_number(c.program_end), MRole::End},
                       {m_number(c.spindle_cw), MRole::SpindleCw},
                       {m_number(c.spindle_ccw), MRole::SpindleCcw},
                       {m_number(c.spindle_stop), MRole::SpindleStop},
                       {m_number(c.tool_change), MRole::ToolChange},
                       {m_number(c.coolant_on), MRole::CoolantOn},
                       {m_number(c.coolant_off), MRole::CoolantOff}}};

  if (machine.heads.size() > static_cast<std::size_t>(kMaxHeads))
    throw InputError("machine " + machine.name + ": the G-code interpreter tracks at most " +
                     std::to_string(kMaxHeads) + " heads, the machine has " + std::to_string(machine.heads.size()));
  const Parser code_parser("machine " + machine.name);
  Block code;
  for (std::size_t i = 0; i < machine.heads.size(); ++i) {
    const config::AdditiveHead& h = machine.heads[i];
    for (bool on : {true, false}) {
      const std::string& text = on ? h.codes.on : h.codes.off;
      const std::string what = "heads[" + std::to_string(i) + "].codes." + (on ? "on" : "off") + " '" + text + "'";
      try {
        code_parser.parse_line(text, 1, code);
      } catch (const GcodeError& e) {
        throw InputError("machine " + machine.name + ": " + what + ": " + e.message());
      }
      if (code.m_count != 1 || code.g_count != 0 || (code.letters & ~(bit('P') | bit('E') | bit('Q') | bit('S'))) != 0)
        throw InputError("machine " + machine.name + ": " + what +
                         ": expected one M code with optional P, E, Q or S words, such as 'M64 P0'");
      HeadCode hc;
      hc.m = code.m[0].value;
      if (code.has('P') && !number_word(code.value('P')))
        throw InputError("machine " + machine.name + ": " + what +
                         ": expected the output number P to be a whole number from 0 to 99999");
      hc.p = code.has('P') ? static_cast<int>(code.value('P')) : -1;
      hc.head = static_cast<int>(i);
      hc.on = on;
      head_codes_.push_back(hc);
    }
  }
}

Interpreter::MRole Interpreter::role_of(int m) const {
  for (const auto& [number, role] : machine_m_codes_)
    if (number == m) return role;
  switch (m) {
    case 0: return MRole::Stop;
    case 1: return MRole::OptionalStop;
    case 2:
    case 30: return MRole::End;
    case 3: return MRole::SpindleCw;
    case 4: return MRole::SpindleCcw;
    case 5: return MRole::SpindleStop;
    case 6: return MRole::ToolChange;
    case 7:
    case 8: return MRole::CoolantOn;
    case 9: return MRole::CoolantOff;
    default: return MRole::None;
  }
}

void Interpreter::fail(const Block& b, int column, const std::string& message) const {
  throw GcodeError(parser_.file_name(), b.line, column, message);
}

const LineResult& Interpreter::execute_line(std::string_view text, int line_number) {
  result_.clear();
  parser_.parse_line(text, line_number, block_);
  return execute(block_);
}

const LineResult& Interpreter::execute(const Block& b) {
  result_.clear();
  ModalState next = state_;
  try {
    run(b, next);
  } catch (...) {
    result_.clear();
    throw;
  }
  state_ = next;
  if (b.no_words()) {
    if (!b.comment.empty()) pending_comment_.assign(b.comment);
  } else {
    pending_comment_.clear();
  }
  return result_;
}

void Interpreter::run(const Block& b, ModalState& s) {
  if (b.no_words()) return;
  if (b.program_number >= 0) return;  // a Fanuc O line: the parser allows nothing else on it
  if (s.ended)
    fail(b,
         b.g_count   ? b.g[0].column
         : b.m_count ? b.m[0].column
                     : 1,
         "found words after the program end; expected nothing but comments or '%' after M2/M30");

  std::uint32_t used = 0;  // letters some code used

  // ---- G codes by modal group
  struct Slot {
    int code = -1;
    int column = 0;
  };
  Slot motion, plane, distance, arc_distance, feed_mode, units, cutter, length, coords, path, dwell, machine_coords;
  for (int i = 0; i < b.g_count; ++i) {
    const Code c = b.g[i];
    Slot* slot = nullptr;
    const char* group = "";
    switch (c.value) {
      case 0:
      case 10:
      case 20:
      case 30:
      case 800:
        slot = &motion;
        group = "motion";
        break;
      case 170:
      case 180:
      case 190:
        slot = &plane;
        group = "plane";
        break;
      case 900:
      case 910:
        slot = &distance;
        group = "distance mode";
        break;
      case 901:
      case 911:
        slot = &arc_distance;
        group = "arc distance mode";
        break;
      case 940:
        slot = &feed_mode;
        group = "feed mode";
        break;
      case 200:
      case 210:
        slot = &units;
        group = "units";
        break;
      case 400:
        slot = &cutter;
        group = "cutter compensation";
        break;
      case 430:
      case 490:
        slot = &length;
        group = "tool length offset";
        break;
      case 540:
      case 550:
      case 560:
      case 570:
      case 580:
      case 590:
        slot = &coords;
        group = "work offset";
        break;
      case 610:
      case 611:
      case 640:
        slot = &path;
        group = "path control";
        break;
      case 40:
        slot = &dwell;
        group = "non-modal";
        break;
      case 530:
        slot = &machine_coords;
        group = "non-modal";
        break;
      case 930: fail(b, c.column, "found G93: inverse time feed is not supported; expected G94 (units per minute)");
      case 410:
      case 420:
        fail(b, c.column,
             "found " + g_code_name(c.value) +
                 ": cutter radius compensation is not supported; expected toolpaths of the tool centre "
                 "(G40)");
      default:
        fail(b, c.column,
             "found " + g_code_name(c.value) + ", an unknown or unsupported G code; expected one of " + kKnownG);
    }
    if (slot->code >= 0)
      fail(b, c.column,
           "found " + g_code_name(c.value) + " after " + g_code_name(slot->code) + " on one line: two codes of the " +
               group + " group; expected at most one");
    *slot = {c.value, c.column};
  }
  if (dwell.code >= 0 && motion.code >= 0)
    fail(b, dwell.column, "found G4 with " + g_code_name(motion.code) + "; expected G4 on a line without motion codes");

  // ---- M codes: each has one role; one code per group and line
  enum Group { kStop, kToolChange, kSpindle, kCoolant, kIo, kGroups };
  std::array<int, kGroups> group_column{};
  struct MAction {
    MRole role = MRole::None;
    int head_code = -1;  // index into head_codes_
    int io = 0;          // 62..68 for generic I/O
    int column = 0;
    int m = 0;
  };
  std::array<MAction, Block::kMaxCodes> actions{};
  int action_count = 0;
  int tool_after_change = s.tool;
  for (int i = 0; i < b.m_count; ++i)
    if (role_of(b.m[i].value) == MRole::ToolChange)
      // (a T that is no tool number is refused below, with its column)
      tool_after_change = !b.has('T') ? s.selected_tool : number_word(b.value('T')) ? int(b.value('T')) : -1;
  for (int i = 0; i < b.m_count; ++i) {
    const Code c = b.m[i];
    MAction a;
    a.column = c.column;
    a.m = c.value;
    // A head's code first: M62..M65-style codes match on P; a code that is also a
    // spindle or coolant code (e.g. M3 for a wire-arc torch) only while that head is active.
    for (std::size_t k = 0; k < head_codes_.size(); ++k) {
      const HeadCode& hc = head_codes_[k];
      if (hc.m != c.value) continue;
      if (hc.p >= 0 && !(b.has('P') && b.value('P') == hc.p)) continue;
      const MRole role = role_of(c.value);
      if (role != MRole::None && tool_after_change != machine_.heads[static_cast<std::size_t>(hc.head)].tool_number)
        continue;
      a.head_code = static_cast<int>(k);
      break;
    }
    Group group = kIo;
    if (a.head_code >= 0) {
      if (head_codes_[static_cast<std::size_t>(a.head_code)].p >= 0) used |= bit('P');
    } else {
      a.role = role_of(c.value);
      switch (a.role) {
        case MRole::Stop:
        case MRole::OptionalStop:
        case MRole::End: group = kStop; break;
        case MRole::ToolChange: group = kToolChange; break;
        case MRole::SpindleCw:
        case MRole::SpindleCcw:
        case MRole::SpindleStop: group = kSpindle; break;
        case MRole::CoolantOn:
        case MRole::CoolantOff: group = kCoolant; break;
        case MRole::None:
          if ((c.value >= 62 && c.value <= 65) || c.value == 67 || c.value == 68) {
            a.io = c.value;
          } else {
            fail(b, c.column,
                 "found " + m_code_name(c.value) +
                     ", an unknown M code; expected M0, M1, M2, M3, M4, M5, M6, M7, M8, M9, M30, "
                     "M62..M65, M67, M68 or one of the machine's codes (gcode.m_codes, "
                     "heads[].codes)");
          }
          break;
      }
    }
    if (group_column[group] != 0)
      fail(b, c.column,
           "found " + m_code_name(c.value) + " and another M code of the same group (column " +
               std::to_string(group_column[group]) + ") on one line; expected at most one");
    group_column[group] = c.column;
    actions[static_cast<std::size_t>(action_count++)] = a;
  }

  // ---- units first: they apply to every number on the line
  if (units.code >= 0) s.inches = units.code == 200;
  const double unit = s.inches ? kMmPerInch : 1.0;

  // ---- F, S, T
  if (b.has('F')) {
    const double f = b.value('F');
    if (f < 0) fail(b, b.column('F'), "found F" + fmt(f) + "; expected a feed rate of 0 or more");
    s.feed = f * unit;
    used |= bit('F');
  }
  if (b.has('S')) {
    const double v = b.value('S');
    if (v < 0) fail(b, b.column('S'), "found S" + fmt(v) + "; expected a spindle speed of 0 or more");
    s.spindle_speed = v;
    used |= bit('S');
  }
  if (b.has('T')) {
    const double t = b.value('T');
    if (!number_word(t))
      fail(b, b.column('T'), "found T" + fmt(t) + "; expected a tool number, a whole number from 0 to 99999");
    s.selected_tool = static_cast<int>(t);
    used |= bit('T');
  }

  auto event = [&](EventKind kind, int column) -> Event& {
    Event& e = result_.events.emplace_back();
    e.line = b.line;
    e.column = column;
    e.kind = kind;
    return e;
  };

  // ---- tool change, spindle, coolant, outputs (LinuxCNC's order of execution)
  for (int i = 0; i < action_count; ++i) {
    const MAction& a = actions[static_cast<std::size_t>(i)];
    if (a.role != MRole::ToolChange) continue;
    s.tool = s.selected_tool;
    s.spindle = SpindleState::Off;  // as LinuxCNC's M6 does
    event(EventKind::ToolChange, a.column).tool = s.tool;
  }
  for (int i = 0; i < action_count; ++i) {
    const MAction& a = actions[static_cast<std::size_t>(i)];
    if (a.head_code >= 0) continue;
    if (a.role == MRole::SpindleCw || a.role == MRole::SpindleCcw) {
      s.spindle = a.role == MRole::SpindleCw ? SpindleState::Cw : SpindleState::Ccw;
      event(EventKind::SpindleStart, a.column).value = s.spindle_speed;
    } else if (a.role == MRole::SpindleStop) {
      s.spindle = SpindleState::Off;
      event(EventKind::SpindleStop, a.column);
    }
  }
  for (int i = 0; i < action_count; ++i) {
    const MAction& a = actions[static_cast<std::size_t>(i)];
    if (a.head_code >= 0) continue;
    if (a.role == MRole::CoolantOn) {
      s.coolant = true;
      event(EventKind::CoolantOn, a.column);
    } else if (a.role == MRole::CoolantOff) {
      s.coolant = false;
      event(EventKind::CoolantOff, a.column);
    }
  }
  for (int i = 0; i < action_count; ++i) {
    const MAction& a = actions[static_cast<std::size_t>(i)];
    if (a.head_code >= 0) {
      const HeadCode& hc = head_codes_[static_cast<std::size_t>(a.head_code)];
      if (hc.on)
        s.deposition |= 1u << hc.head;
      else
        s.deposition &= ~(1u << hc.head);
      Event& e = event(hc.on ? EventKind::DepositionOn : EventKind::DepositionOff, a.column);
      e.index = hc.head;
      e.tool = machine_.heads[static_cast<std::size_t>(hc.head)].tool_number;
      if (b.has('E')) used |= bit('E');
      if (b.has('Q')) used |= bit('Q');
      continue;
    }
    if (a.io >= 62 && a.io <= 65) {
      if (!b.has('P'))
        fail(b, a.column,
             "found " + m_code_name(a.io) + " with no P word; expected the output number, e.g. " + m_code_name(a.io) +
                 " P0");
      const double p = b.value('P');
      if (!number_word(p))
        fail(b, b.column('P'),
             "found P" + fmt(p) + " with " + m_code_name(a.io) +
                 "; expected an output number, a whole number from 0 to 99999");
      used |= bit('P');
      Event& e = event(EventKind::DigitalOutput, a.column);
      e.index = static_cast<int>(p);
      e.value = (a.io == 62 || a.io == 64) ? 1.0 : 0.0;
    } else if (a.io == 67 || a.io == 68) {
      if (!b.has('E') || !b.has('Q'))
        fail(b, a.column,
             "found " + m_code_name(a.io) + " without " + (b.has('E') ? "Q" : "E") +
                 "; expected the output number E and its value Q, e.g. " + m_code_name(a.io) + " E0 Q800");
      const double e_number = b.value('E');
      if (!number_word(e_number))
        fail(b, b.column('E'),
             "found E" + fmt(e_number) + "; expected an analog output number, a whole number from 0 to 99999");
      used |= bit('E') | bit('Q');
      Event& e = event(EventKind::AnalogOutput, a.column);
      e.index = static_cast<int>(e_number);
      e.value = b.value('Q');
    }
  }

  // ---- dwell: RS274NGC G4 P<seconds>; Fanuc G4 X<seconds> or G4 P<milliseconds>
  std::uint32_t dwell_letters = 0;
  if (dwell.code >= 0) {
    const bool fanuc = machine_.gcode.dialect == config::Dialect::Fanuc;
    char letter = 'P';
    if (fanuc && b.has('X')) letter = 'X';
    if (!b.has(letter))
      fail(b, dwell.column,
           fanuc ? "found G4 with no X or P word; expected the dwell as X<seconds> or P<milliseconds>, e.g. G4 X0.5"
                 : "found G4 with no P word; expected the dwell time in seconds, e.g. G4 P0.5");
    const double value = b.value(letter);
    if (value < 0)
      fail(b, b.column(letter), "found " + std::string(1, letter) + fmt(value) + " with G4; expected a dwell of 0 or more");
    dwell_letters = bit(letter);
    used |= dwell_letters;
    event(EventKind::Dwell, dwell.column).value = fanuc && letter == 'P' ? value / 1000.0 : value;
  }

  // ---- modes
  if (plane.code >= 0) s.plane = plane.code == 170 ? Plane::XY : plane.code == 180 ? Plane::ZX : Plane::YZ;
  if (length.code == 430) {
    if (!b.has('H'))
      fail(b, length.column, "found G43 with no H word; expected the tool length offset number, e.g. G43 H1");
    const double h = b.value('H');
    if (!number_word(h))
      fail(b, b.column('H'), "found H" + fmt(h) + "; expected a tool number, a whole number from 0 to 99999");
    s.tool_length_offset = static_cast<int>(h);
    used |= bit('H');
  } else if (length.code == 490) {
    s.tool_length_offset = 0;
  }
  if (coords.code >= 0) {
    const int offset = coords.code / 10;
    const config::Setup* setup = machine_.find_setup_by_work_offset(offset);
    if (!setup) {
      std::string known;
      for (const auto& st : machine_.setups)
        known += (known.empty() ? "" : ", ") + std::string("G") + std::to_string(st.work_offset) + " (" + st.name + ")";
      fail(b, coords.column,
           "found G" + std::to_string(offset) + ", a work offset no setup of machine '" + machine_.name +
               "' uses; expected one of " + known);
    }
    s.work_offset = offset;
    s.offset = {setup->work_origin[0], setup->work_origin[1], setup->work_origin[2]};
    event(EventKind::WorkOffset, coords.column).index = offset;
  }
  if (distance.code >= 0) s.absolute = distance.code == 900;
  if (arc_distance.code >= 0) s.arc_absolute = arc_distance.code == 901;

  // ---- motion
  if (motion.code >= 0) {
    s.motion_active = motion.code != 800;
    if (s.motion_active)
      s.motion = motion.code == 0    ? MotionKind::Rapid
                 : motion.code == 10 ? MotionKind::Feed
                 : motion.code == 20 ? MotionKind::ArcCw
                                     : MotionKind::ArcCcw;
  }
  const std::uint32_t axis_words = b.letters & kAxisLetters & ~dwell_letters;
  int first_axis_column = 0;
  for (char L : {'X', 'Y', 'Z', 'A', 'B', 'C'})
    if ((axis_words & bit(L)) && (first_axis_column == 0 || b.column(L) < first_axis_column)) first_axis_column = b.column(L);
  if (machine_coords.code >= 0) {
    if (!s.motion_active || (s.motion != MotionKind::Rapid && s.motion != MotionKind::Feed))
      fail(b, machine_coords.column,
           "found G53 without G0 or G1; expected G53 G0 or G53 G1 (machine coordinates "
           "apply to straight moves only)");
    if (!s.absolute)
      fail(b, machine_coords.column,
           "found G53 in incremental mode (G91); expected G90 for moves in machine "
           "coordinates");
  }
  // LinuxCNC runs a G2/G3 with centre offsets and no axis words as a full circle.
  const bool arc_mode = s.motion_active && (s.motion == MotionKind::ArcCw || s.motion == MotionKind::ArcCcw);
  if (axis_words != 0 || (arc_mode && (b.letters & kArcLetters) != 0)) {
    if (!s.motion_active)
      fail(b, first_axis_column,
           "found axis words with no motion mode in effect; expected G0, G1, G2 or G3 on "
           "this or an earlier line");
    used |= axis_words;
    Motion m;
    m.line = b.line;
    m.kind = s.motion;
    m.from_machine = s.position;
    m.from_rotary = s.rotary;
    Vec3 to = s.position;
    Rotary rot = s.rotary;
    const char letters[3] = {'X', 'Y', 'Z'};
    for (int axis = 0; axis < 3; ++axis) {
      const char L = letters[axis];
      if (!b.has(L)) continue;
      const double v = b.value(L) * unit;
      if (machine_coords.code >= 0)
        at(to, axis) = v;
      else
        at(to, axis) = s.absolute ? at(s.offset, axis) + v : at(s.position, axis) + v;
    }
    if (b.has('A')) rot.a = s.absolute || machine_coords.code >= 0 ? b.value('A') : rot.a + b.value('A');
    if (b.has('B')) rot.b = s.absolute || machine_coords.code >= 0 ? b.value('B') : rot.b + b.value('B');
    if (b.has('C')) rot.c = s.absolute || machine_coords.code >= 0 ? b.value('C') : rot.c + b.value('C');
    m.to_machine = to;
    m.to_rotary = rot;
    // With no motion code on the line, its first axis word stands for the motion; a modal
    // G2/G3 line may hold only arc words (a full circle: I J K; or R), then the first of those.
    int first_motion_word_column = first_axis_column;
    if (arc_mode && first_motion_word_column == 0)
      for (char L : {'I', 'J', 'K', 'R'})
        if (b.has(L) && (first_motion_word_column == 0 || b.column(L) < first_motion_word_column))
          first_motion_word_column = b.column(L);
    const int motion_column = motion.code >= 0 ? motion.column : first_motion_word_column;
    if (m.kind != MotionKind::Rapid) {
      if (s.feed <= 0)
        fail(b, motion_column,
             "found " +
                 std::string(m.kind == MotionKind::Feed                  ? "G1"
                             : m.is_arc() && m.kind == MotionKind::ArcCw ? "G2"
                                                                         : "G3") +
                 " with zero feed rate; expected an F word greater than 0 on this or an earlier line");
      m.feed = s.feed;
    }
    if (m.is_arc()) {
      const PlaneAxes pa = axes_of(s.plane);
      const char* gname = m.kind == MotionKind::ArcCw ? "G2" : "G3";
      const std::uint32_t arc_words = b.letters & kArcLetters;
      const std::uint32_t plane_offsets = bit(pa.first_offset) | bit(pa.second_offset);
      for (char L : {'I', 'J', 'K'})
        if (b.has(L) && !(plane_offsets & bit(L)))
          fail(b, b.column(L),
               "found " + std::string(1, L) + " with " + gname + " in the " + pa.name + " plane; expected only " +
                   pa.first_offset + " and " + pa.second_offset + " (or R) for arcs in that plane");
      const double x0 = at(s.position, pa.first), y0 = at(s.position, pa.second);
      const double x1 = at(to, pa.first), y1 = at(to, pa.second);
      double cx = 0, cy = 0;
      if (b.has('R')) {
        if (arc_words & plane_offsets)
          fail(b, b.column('R'),
               std::string("found R with ") + pa.first_offset + "/" + pa.second_offset +
                   " offsets; expected either a radius R or centre offsets, not both");
        const char first_letter = letters[pa.first], second_letter = letters[pa.second];
        if (!b.has(first_letter) && !b.has(second_letter))
          fail(b, motion_column,
               "found " + std::string(gname) + " with R and no " + pa.axes +
                   " word; expected the arc's end point in the " + pa.name +
                   " plane (an R arc cannot be a full circle)");
        const double radius = b.value('R') * unit;
        if (x0 == x1 && y0 == y1)
          fail(b, b.column('R'),
               "found an R arc that ends where it starts; expected a different end point (use I/J "
               "offsets for a full circle)");
        const double abs_radius = std::abs(radius);
        const double mx = 0.5 * (x0 + x1), my = 0.5 * (y0 + y1);
        double half = std::hypot(x1 - mx, y1 - my);
        if (half - abs_radius > kRadiusTolerance)
          fail(b, b.column('R'),
               "found R" + fmt(b.value('R')) + ", too small to reach the end point (half the chord is " +
                   fmt(half / unit) + "); expected a radius of at least " + fmt(half / unit));
        if (half / abs_radius > 1 - 1e-12) half = abs_radius;
        const bool cw = m.kind == MotionKind::ArcCw;
        double theta = std::atan2(y1 - y0, x1 - x0) + ((cw && radius > 0) || (!cw && radius < 0) ? -M_PI_2 : M_PI_2);
        const double offset = abs_radius * std::cos(std::asin(half / abs_radius));
        cx = mx + offset * std::cos(theta);
        cy = my + offset * std::sin(theta);
        used |= bit('R');
      } else {
        if (!(arc_words & plane_offsets))
          fail(b, motion_column,
               "found " + std::string(gname) + " with no " + pa.first_offset + ", " + pa.second_offset +
                   " or R; expected the centre as " + pa.first_offset + "/" + pa.second_offset +
                   " offsets or a radius R");
        const double i = b.has(pa.first_offset) ? b.value(pa.first_offset) * unit : 0.0;
        const double j = b.has(pa.second_offset) ? b.value(pa.second_offset) * unit : 0.0;
        if (s.arc_absolute) {
          cx = at(s.offset, pa.first) + i;
          cy = at(s.offset, pa.second) + j;
        } else {
          cx = x0 + i;
          cy = y0 + j;
        }
        const double r0 = std::hypot(x0 - cx, y0 - cy), r1 = std::hypot(x1 - cx, y1 - cy);
        const int column = b.has(pa.first_offset) ? b.column(pa.first_offset) : b.column(pa.second_offset);
        if (r0 < kRadiusTolerance || r1 < kRadiusTolerance)
          fail(b, column,
               "found an arc of zero radius (start radius " + fmt(r0 / unit) + ", end radius " + fmt(r1 / unit) +
                   "); expected the centre away from the start and end points");
        const double abs_err = std::abs(r0 - r1);
        const double rel_err = abs_err / std::max(r0, r1);
        if (abs_err > options_.arc_radius_tolerance || rel_err > options_.arc_relative_tolerance)
          fail(b, column,
               "radius to end of arc differs from radius to start: start radius " + fmt(r0 / unit) + ", end radius " +
                   fmt(r1 / unit) + " (difference " + fmt(abs_err / unit) + "); expected them equal within " +
                   fmt(options_.arc_radius_tolerance) + " mm and " + fmt(options_.arc_relative_tolerance * 100) + " %");
        used |= arc_words & plane_offsets;
      }
      Vec3 centre = s.position;
      at(centre, pa.first) = cx;
      at(centre, pa.second) = cy;
      m.centre_machine = centre;
      m.centre_work = {centre.x - s.offset.x, centre.y - s.offset.y, centre.z - s.offset.z};
      m.plane = s.plane;
    }
    m.from_work = {m.from_machine.x - s.offset.x, m.from_machine.y - s.offset.y, m.from_machine.z - s.offset.z};
    m.to_work = {to.x - s.offset.x, to.y - s.offset.y, to.z - s.offset.z};
    m.tool = s.tool;
    m.work_offset = machine_coords.code >= 0 ? 53 : s.work_offset;
    m.spindle = s.spindle;
    m.spindle_speed = s.spindle_speed;
    m.deposition = s.any_deposition();
    m.coolant = s.coolant;
    s.position = to;
    s.rotary = rot;
    result_.motions.push_back(m);
  } else if (machine_coords.code >= 0) {
    fail(b, machine_coords.column, "found G53 with no axis words; expected the machine coordinates to move to");
  }

  // ---- words no code used
  const std::uint32_t always = bit('F') | bit('S') | bit('T');
  const std::uint32_t unused = b.letters & ~used & ~always;
  if (unused != 0) {
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
      fail(b, b.column(L),
           "found " + std::string(1, L) + fmt(b.value(L)) + " with nothing on the line to use it; " + why);
    }
  }

  // ---- stops and program end, after the motion
  for (int i = 0; i < action_count; ++i) {
    const MAction& a = actions[static_cast<std::size_t>(i)];
    if (a.head_code >= 0) continue;
    if (a.role == MRole::Stop || a.role == MRole::OptionalStop) {
      Event& e = event(a.role == MRole::Stop ? EventKind::ProgramStop : EventKind::OptionalStop, a.column);
      e.after_motion = true;
      std::string_view message = !b.comment.empty() ? b.comment : std::string_view(pending_comment_);
      if (message.size() >= 4 && (message.substr(0, 4) == "MSG," || message.substr(0, 4) == "msg,")) {
        message.remove_prefix(4);
        while (!message.empty() && message.front() == ' ') message.remove_prefix(1);
      }
      e.message.assign(message);
    } else if (a.role == MRole::End) {
      event(EventKind::ProgramEnd, a.column).after_motion = true;
      s.ended = true;
      s.spindle = SpindleState::Off;
      s.coolant = false;
      s.absolute = true;
      s.plane = Plane::XY;
    }
  }
}

Program interpret(std::string_view text, const config::Machine& machine, std::string file_name,
                  InterpreterOptions options) {
  Interpreter interpreter(machine, std::move(file_name), std::move(options));
  Program program;
  for_each_line(text, [&](std::string_view line, int number) {
    const LineResult& r = interpreter.execute_line(line, number);
    program.motions.insert(program.motions.end(), r.motions.begin(), r.motions.end());
    program.events.insert(program.events.end(), r.events.begin(), r.events.end());
    program.lines = number;
  });
  return program;
}

}  // namespace hybridctl::gcode
