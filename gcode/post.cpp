#include "gcode/post.hpp"

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "common/error.hpp"
#include "config/machine_loader.hpp"
#include "gcode/check.hpp"
#include "gcode/files.hpp"
#include "gcode/interpreter.hpp"
#include "gcode/parser.hpp"

namespace hybridctl::gcode {

namespace {

using config::Dialect;

/// Larger magnitudes are not coordinates but garbage; they are refused.
constexpr double kMaxMagnitude = 1e9;

// ------------------------------------------------------------------ numbers

void append_integer(std::string& out, std::uint64_t v) {
  char digits[24];
  int n = 0;
  do {
    digits[n++] = static_cast<char>('0' + v % 10);
    v /= 10;
  } while (v != 0);
  while (n > 0) out += digits[--n];
}

// ------------------------------------------------------------------ codes

/// The M number of a code such as "M64 P0", or -1.
int leading_m(const std::string& code) {
  const Parser parser("code");
  Block b;
  try {
    parser.parse_line(code, 1, b);
  } catch (const GcodeError&) {
    return -1;
  }
  return b.m_count == 1 && b.g_count == 0 ? b.m[0].value : -1;
}

}  // namespace

std::optional<PostingProblem> posting_problem(const config::Machine& machine, config::Dialect dialect) {
  if (dialect != Dialect::Rs274ngc) return std::nullopt;
  const Parser parser("machine " + machine.name);
  Block b;
  for (std::size_t i = 0; i < machine.heads.size(); ++i) {
    const config::AdditiveHead& h = machine.heads[i];
    const std::string key = "heads[" + std::to_string(i) + "]";
    const std::string head = key + " (" + h.name + ")";
    for (bool on : {true, false}) {
      const std::string& code = on ? h.codes.on : h.codes.off;
      bool ok = false;
      try {
        parser.parse_line(code, 1, b);
        ok = b.m_count == 1 && b.g_count == 0 && b.m[0].value >= 62 && b.m[0].value <= 65 &&
             b.letters == (1u << ('P' - 'A')) && b.value('P') >= 0 && b.value('P') == std::floor(b.value('P'));
      } catch (const GcodeError&) {
      }
      if (!ok)
        return PostingProblem{key + ".codes." + (on ? "on" : "off"),
                              head + ".codes." + (on ? "on" : "off") + " '" + code +
                                  "' is not a LinuxCNC output code; expected M62/M64 P<n> to switch on and M63/M65 P<n> to "
                                  "switch off (printer codes such as M104 are rejected by LinuxCNC)"};
    }
    if (h.codes.power_template) {
      std::string code = *h.codes.power_template;
      code.replace(code.find("{power}"), 7, "0");
      bool ok = false;
      try {
        parser.parse_line(code, 1, b);
        ok = b.m_count == 1 && b.g_count == 0 && (b.m[0].value == 67 || b.m[0].value == 68) &&
             b.letters == ((1u << ('E' - 'A')) | (1u << ('Q' - 'A')));
      } catch (const GcodeError&) {
      }
      if (!ok)
        return PostingProblem{key + ".codes.power", head + ".codes.power '" + *h.codes.power_template +
                                                        "' is not a LinuxCNC analog output code; expected M68 E<n> Q{power} (or M67)"};
    }
  }
  const config::MCodes& c = machine.gcode.m_codes;
  const std::pair<const char*, std::pair<const std::string*, std::vector<int>>> codes[] = {
      {"program_stop", {&c.program_stop, {0, 1, 60}}}, {"optional_stop", {&c.optional_stop, {1}}},
      {"program_end", {&c.program_end, {2, 30}}},      {"spindle_cw", {&c.spindle_cw, {3}}},
      {"spindle_ccw", {&c.spindle_ccw, {4}}},          {"spindle_stop", {&c.spindle_stop, {5}}},
      {"tool_change", {&c.tool_change, {6}}},          {"coolant_on", {&c.coolant_on, {7, 8}}},
      {"coolant_off", {&c.coolant_off, {9}}}};
  for (const auto& [name, entry] : codes) {
    const int m = leading_m(*entry.first);
    bool ok = false;
    std::string expected;
    for (int allowed : entry.second) {
      ok = ok || m == allowed;
      expected += (expected.empty() ? "M" : " or M") + std::to_string(allowed);
    }
    if (!ok)
      return PostingProblem{std::string("gcode.m_codes.") + name,
                            std::string("gcode.m_codes.") + name + " " + *entry.first +
                                " is not the code LinuxCNC runs for it; expected " + expected +
                                " (or write this machine's programs in the fanuc dialect)"};
  }
  return std::nullopt;
}

namespace {

/// The RS274NGC dialect writes only codes LinuxCNC runs. Throws InputError naming the key.
void require_linuxcnc_codes(const config::Machine& machine) {
  if (const auto problem = posting_problem(machine, Dialect::Rs274ngc))
    throw InputError("machine '" + machine.name + "' (rs274ngc dialect): " + problem->message);
}

// ------------------------------------------------------------------ the writer

/// What produced a generated line, for error messages.
struct Origin {
  int action = -1;        ///< index into the actions, -1 for the program's header and end
  int move = -1;          ///< index into the action's moves, -1 for generated lines
  const char* what = "";  ///< for generated lines: "header", "approach", ...
};

struct Instrument {
  int number = 0;
  const config::AdditiveHead* head = nullptr;
  const config::CuttingTool* tool = nullptr;
};

Instrument resolve_instrument(const ActionProgram& a, const config::Machine& machine, const std::string& where) {
  Instrument in;
  const Toolpath& p = a.path;
  if (p.tool_number != 0) {
    in.number = p.tool_number;
    in.head = machine.find_head_by_tool(p.tool_number);
    in.tool = machine.find_tool(p.tool_number);
  } else if (p.process == Process::Deposition) {
    in.head = machine.find_head(p.instrument);
    if (in.head) in.number = in.head->tool_number;
  } else {
    for (const auto& t : machine.tools)
      if (t.name == p.instrument) in.tool = &t;
    if (in.tool) in.number = in.tool->number;
  }
  if (p.process == Process::Deposition && !in.head)
    throw InputError(where + ": deposition with " +
                     (p.tool_number ? "T" + std::to_string(p.tool_number) : "'" + p.instrument + "'") +
                     ", which is not a head of machine '" + machine.name + "'; expected a head's tool_number or name");
  if (p.process == Process::Milling && !in.tool)
    throw InputError(
        where + ": milling with " + (p.tool_number ? "T" + std::to_string(p.tool_number) : "'" + p.instrument + "'") +
        ", which is not a cutting tool of machine '" + machine.name + "'; expected a cutting tool's number or name");
  return in;
}

/// The action's row in the program's table (its lines are filled in as they are written).
ProgramAction table_row(const ActionProgram& a, const Instrument& in, const config::Setup& setup) {
  ProgramAction row;
  row.number = a.action;
  row.primitive = comment_text(a.primitive);
  row.mode = a.additive ? ActionMode::Additive : ActionMode::Subtractive;
  row.process = a.path.process;
  row.instrument = comment_text(in.head ? "head " + in.head->name : "T" + std::to_string(in.number) + " " + in.tool->name);
  row.setup = comment_text(setup.name);
  return row;
}

class Writer {
 public:
  Writer(const config::Machine& machine, Dialect dialect, const PostOptions& options)
      : machine_(machine), dialect_(dialect), options_(options), fanuc_(dialect == Dialect::Fanuc) {}

  std::vector<std::string> lines;
  std::vector<Origin> origins;         ///< by generated line - 1
  std::vector<ProgramAction> table;    ///< the program's actions, in order

  void program(const std::vector<const ActionProgram*>& actions, int program_number) {
    // Everything that can be refused without writing is checked first.
    if (dialect_ == Dialect::Rs274ngc) require_linuxcnc_codes(machine_);
    std::vector<Instrument> instruments;
    std::vector<const config::Setup*> setups;
    for (const ActionProgram* a : actions) {
      const std::string where = action_name(*a);
      instruments.push_back(resolve_instrument(*a, machine_, where));
      const config::Setup* setup = machine_.find_setup(a->path.setup);
      if (!setup)
        throw InputError(where + ": setup '" + a->path.setup + "' is not a setup of machine '" + machine_.name + "'");
      setups.push_back(setup);
    }

    origin_ = {-1, -1, "header"};
    if (fanuc_) {
      raw_line("%");
      raw_line("O" + std::to_string(program_number) + " (" + comment_text(options_.program_name) + ")");
    } else {
      comment(options_.program_name);
    }
    comment("machine " + machine_.name + ", dialect " + std::string(config::to_string(dialect_)) + ", " +
            std::to_string(actions.size()) + (actions.size() == 1 ? " action" : " actions"));
    comment("generated by hybridctl: work coordinates, mm");
    line("G21 G90 G17 G94 G40 G49 G80");
    if (!setups.empty()) {
      line("G" + std::to_string(setups.front()->work_offset));
      setup_ = setups.front();
    }
    for (std::size_t i = 0; i < actions.size(); ++i)
      action(*actions[i], static_cast<int>(i), instruments[i], *setups[i]);
    origin_ = {-1, -1, "program end"};
    stop_everything();
    retract_to_top();
    line(machine_.gcode.m_codes.program_end);
    if (fanuc_) raw_line("%");
  }

 private:
  static std::string action_name(const ActionProgram& a) {
    return "action " + std::to_string(a.action) + " (" + a.primitive + (a.label.empty() ? "" : ", " + a.label) + ")";
  }

  void raw_line(std::string_view s) {
    lines.emplace_back(s);
    origins.push_back(origin_);
  }
  void line(std::string_view s) {
    std::string& text = lines.emplace_back();
    if (fanuc_) {
      block_number_ += 10;
      text += 'N';
      append_integer(text, static_cast<std::uint64_t>(block_number_));
      text += ' ';
    }
    text += s;
    origins.push_back(origin_);
  }
  void comment(std::string_view s) { line("(" + comment_text(s) + ")"); }
  void number(std::string& out, double v) { append_number(out, v, fanuc_); }

  /// A coordinate as the program writes it (append_number's rounding to 0.0001 mm).
  static double written(double v) { return std::round(v * 10000.0) / 10000.0; }

  void forget_position() { known_[0] = known_[1] = known_[2] = false; }

  void retract_to_top() {
    if (retracted_) return;
    std::string s = "G53 G0 Z";
    number(s, machine_.envelope.z.travel.max);
    line(s);
    retracted_ = true;
    forget_position();
  }

  void stop_everything() {
    if (deposition_head_) {
      line(deposition_head_->codes.off);
      deposition_head_ = nullptr;
    }
    stop_milling();
  }

  // Spindle, then coolant, off where they are on.
  void stop_milling() {
    if (spindle_on_) {
      line(machine_.gcode.m_codes.spindle_stop);
      spindle_on_ = false;
    }
    if (coolant_on_) {
      line(machine_.gcode.m_codes.coolant_off);
      coolant_on_ = false;
    }
  }

  void action(const ActionProgram& a, int index, const Instrument& in, const config::Setup& setup) {
    const Toolpath& p = a.path;
    origin_ = {index, -1, "action start"};
    table.push_back(table_row(a, in, setup));
    table.back().first_line = static_cast<std::uint32_t>(lines.size() + 1);
    comment(table.back().heading());
    if (!a.label.empty()) comment(a.label);
    std::string summary = "volume ";
    append_number(summary, a.volume);
    summary += " mm3, toolpath motion " + format_duration(estimated_time(a, setup)) + ", " +
               std::to_string(p.moves.size()) + " moves";
    comment(summary);
    for (const auto& w : p.warnings) comment("warning: " + w);

    const bool tool_change = in.number != tool_;
    const bool setup_change = &setup != setup_ || !rotary_done_;
    const bool rotary_move = setup_change && rotary_axes(setup);
    const bool stop_for_setup = &setup != setup_ && (setup.manual_refixture || !rotary_axes(setup));
    if (tool_change || rotary_move || stop_for_setup) {
      origin_.what = tool_change ? "tool change" : "setup change";
      stop_everything();
      retract_to_top();
    }
    if (tool_change) {
      origin_.what = "tool change";
      line("T" + std::to_string(in.number) + " " + machine_.gcode.m_codes.tool_change);
      line("G43 H" + std::to_string(in.number));
      tool_ = in.number;
    }
    if (setup_change) {
      origin_.what = "setup change";
      if (rotary_move) {
        std::string s = "G0";
        for (const auto& r : setup.rotary) {
          if (!machine_.envelope.find_rotary(r.axis)) continue;
          s += ' ';
          s += r.axis;
          number(s, r.degrees);
        }
        line(s);
      }
      if (stop_for_setup) {
        const std::string message = "setup " + setup.name +
                                    (setup.description.empty() ? "" : ": " + setup.description) + " - " +
                                    (setup.manual_refixture ? "refixture the part" : "set the part up") + " for " +
                                    std::string(config::to_string(setup.approach)) + ", then cycle start";
        comment(fanuc_ ? message : "MSG, " + message);
        line(machine_.gcode.m_codes.program_stop);
      }
      if (&setup != setup_) line("G" + std::to_string(setup.work_offset));
      setup_ = &setup;
      rotary_done_ = true;
      forget_position();
    }
    origin_.what = "process start";
    if (in.tool) {
      const long rpm = std::lround(in.tool->spindle_speed);
      if (!spindle_on_ || rpm != spindle_rpm_) {
        line("S" + std::to_string(rpm) + " " + machine_.gcode.m_codes.spindle_cw);
        spindle_on_ = true;
        spindle_rpm_ = rpm;
      }
      if (options_.coolant && !coolant_on_) {
        line(machine_.gcode.m_codes.coolant_on);
        coolant_on_ = true;
      }
    } else {
      stop_milling();
      if (in.head->codes.power_template) {
        std::string code = *in.head->codes.power_template;
        code.replace(code.find("{power}"), 7, format_number(in.head->codes.power));
        line(code);
      }
    }

    // Approach the start at safe height: up first if the start is higher, then XY, then Z.
    origin_.what = "approach to the path start";
    if (known_[2] && p.start.z > position_.z)
      move(MoveKind::Rapid, Vec3{position_.x, position_.y, p.start.z}, {}, 0, false);
    move(MoveKind::Rapid, Vec3{p.start.x, p.start.y, 0.0}, {}, 0, true);
    move(MoveKind::Rapid, p.start, {}, 0, false);
    retracted_ = false;

    for (std::size_t k = 0; k < p.moves.size(); ++k) {
      const PathMove& m = p.moves[k];
      origin_ = {index, static_cast<int>(k), "move"};
      if (!m.comment.empty()) comment(m.comment);
      if (in.tool && m.kind != MoveKind::Rapid) {
        // A pass at its own spindle speed (finishing): S before it, and back after.
        const long rpm = std::lround(m.spindle > 0 ? m.spindle : in.tool->spindle_speed);
        if (rpm != spindle_rpm_) {
          line("S" + std::to_string(rpm));
          spindle_rpm_ = rpm;
        }
      }
      if (in.head) {
        const bool on = m.process_on;
        if (on && !deposition_head_) {
          line(in.head->codes.on);
          deposition_head_ = in.head;
        } else if (!on && deposition_head_) {
          line(in.head->codes.off);
          deposition_head_ = nullptr;
        }
      }
      move(m.kind, m.to, m.centre, m.feed, false);
    }
    origin_ = {index, -1, "action end"};
    if (deposition_head_) {
      line(deposition_head_->codes.off);
      deposition_head_ = nullptr;
    }
    move(MoveKind::Rapid, Vec3{position_.x, position_.y, std::max(p.safe_z, position_.z)}, {}, 0, false);
    table[static_cast<std::size_t>(index)].last_line = static_cast<std::uint32_t>(lines.size());
  }

  /// Writes one move in the work frame; axes whose written value does not change are left out.
  void move(MoveKind kind, const Vec3& to, const Vec3& centre, double feed, bool xy_only) {
    for (double v : {to.x, to.y, to.z, centre.x, centre.y, feed})
      if (!std::isfinite(v) || std::abs(v) > kMaxMagnitude)
        throw InputError("a move with a coordinate or feed that is not a finite number below 1e9; got " +
                         format_number(v));
    const bool arc = kind == MoveKind::ArcCw || kind == MoveKind::ArcCcw;
    buffer_.clear();
    buffer_ += kind == MoveKind::Rapid ? "G0" : kind == MoveKind::Feed ? "G1" : kind == MoveKind::ArcCw ? "G2" : "G3";
    bool any_axis = false;
    const double values[3] = {to.x, to.y, to.z};
    for (int axis = 0; axis < 3; ++axis) {
      if (xy_only && axis == 2) continue;
      word_.clear();
      number(word_, values[axis]);
      if (known_[axis] && word_ == last_[axis] && !(arc && axis < 2)) continue;
      buffer_ += ' ';
      buffer_ += "XYZ"[axis];
      buffer_ += word_;
      last_[axis] = word_;
      known_[axis] = true;
      any_axis = true;
    }
    if (arc) {
      // Offsets from the start as written (4 decimals), where the controller is: the centre
      // it computes is then ours to within 0.00005 mm per axis, and its start and end
      // radii agree to about 0.0002 mm (LinuxCNC refuses a difference beyond its tolerance).
      buffer_ += " I";
      number(buffer_, centre.x - written(position_.x));
      buffer_ += " J";
      number(buffer_, centre.y - written(position_.y));
    }
    if (xy_only) {
      position_.x = to.x;
      position_.y = to.y;
    } else {
      position_ = to;
    }
    if (!any_axis && !arc) return;  // nothing moves: no line
    if (kind != MoveKind::Rapid && feed != last_feed_) {
      buffer_ += " F";
      number(buffer_, feed);
      last_feed_ = feed;
    }
    line(buffer_);
  }

  bool rotary_axes(const config::Setup& setup) const {
    for (const auto& r : setup.rotary)
      if (machine_.envelope.find_rotary(r.axis)) return true;
    return false;
  }

  double estimated_time(const ActionProgram& a, const config::Setup& setup) const {
    const Vec3 o{setup.work_origin[0], setup.work_origin[1], setup.work_origin[2]};
    const auto machine_frame = [&o](const Vec3& v) { return Vec3{v.x + o.x, v.y + o.y, v.z + o.z}; };
    double seconds = 0;
    Vec3 from = a.path.start;
    for (const PathMove& pm : a.path.moves) {
      Motion m;
      m.kind = pm.kind == MoveKind::Rapid   ? MotionKind::Rapid
               : pm.kind == MoveKind::Feed  ? MotionKind::Feed
               : pm.kind == MoveKind::ArcCw ? MotionKind::ArcCw
                                            : MotionKind::ArcCcw;
      m.from_machine = machine_frame(from);
      m.to_machine = machine_frame(pm.to);
      m.centre_machine = machine_frame(Vec3{pm.centre.x, pm.centre.y, from.z});
      m.feed = pm.feed;
      seconds += motion_time(m, machine_.envelope);
      from = pm.to;
    }
    return seconds;
  }

  const config::Machine& machine_;
  Dialect dialect_;
  const PostOptions& options_;
  bool fanuc_;
  Origin origin_;
  long block_number_ = 0;
  int tool_ = -1;
  const config::Setup* setup_ = nullptr;
  bool rotary_done_ = false;
  bool spindle_on_ = false;
  long spindle_rpm_ = 0;
  bool coolant_on_ = false;
  const config::AdditiveHead* deposition_head_ = nullptr;
  bool retracted_ = false;
  bool known_[3] = {false, false, false};  ///< the last written X, Y, Z are the controller's position
  Vec3 position_;                          ///< work frame
  std::string last_[3];
  double last_feed_ = -1;
  std::string buffer_, word_;
};

std::string origin_text(const Writer& w, const std::vector<const ActionProgram*>& actions, int line) {
  const std::size_t i = static_cast<std::size_t>(line - 1);
  const Origin& o = w.origins.at(i);
  std::string out;
  if (o.action >= 0) {
    const ActionProgram& a = *actions[static_cast<std::size_t>(o.action)];
    out = "action " + std::to_string(a.action) + " (" + a.primitive + (a.label.empty() ? "" : ", " + a.label) + "), ";
    if (o.move >= 0)
      out += "move " + std::to_string(o.move + 1) + " of " + std::to_string(a.path.moves.size());
    else
      out += o.what;
  } else {
    out = o.what;
  }
  return out + " (generated line " + std::to_string(line) + ": " + w.lines[i] + ")";
}

/// Generates, then proves the text runs on the machine: our interpreter accepts every
/// line and every motion stays in the envelope.
PostedProgram generate(const std::vector<const ActionProgram*>& actions, const config::Machine& machine,
                       const PostOptions& options, int program_number) {
  const Dialect dialect = options.dialect.value_or(machine.gcode.dialect);
  Writer w(machine, dialect, options);
  try {
    w.program(actions, program_number);
  } catch (const InputError& e) {
    throw InputError(std::string("post-processor: ") + e.what() + "; nothing was written");
  }
  Interpreter interpreter(machine, "generated");
  for (std::size_t i = 0; i < w.lines.size(); ++i) {
    const int line = static_cast<int>(i + 1);
    const LineResult* r = nullptr;
    try {
      r = &interpreter.execute_line(w.lines[i], line);
    } catch (const GcodeError& e) {
      throw InputError("post-processor: " + origin_text(w, actions, line) + ": " + e.message() +
                       "; nothing was written");
    }
    for (const Motion& m : r->motions)
      if (auto v = envelope_violation(m, machine.envelope))
        throw InputError("post-processor: " + origin_text(w, actions, line) + " leaves the envelope of machine '" +
                         machine.name + "' (setup work_origin + work coordinates): " + *v + "; nothing was written");
  }
  PostedProgram program;
  program.origins.reserve(w.origins.size());
  for (const Origin& o : w.origins) {
    LineOrigin& to = program.origins.emplace_back();
    if (o.action >= 0) to.action = static_cast<std::size_t>(o.action);
    if (o.move >= 0) to.move = static_cast<std::size_t>(o.move);
  }
  program.lines = std::move(w.lines);
  program.actions = std::move(w.table);
  return program;
}

}  // namespace

void append_number(std::string& out, double value, bool decimal_point) {
  const double scaled = std::round(value * 10000.0);
  if (!std::isfinite(scaled) || std::abs(scaled) >= 9.0e18) {
    out += "0";
    return;
  }
  long long q = static_cast<long long>(scaled);
  if (q < 0) {
    out += '-';
    q = -q;
  }
  append_integer(out, static_cast<std::uint64_t>(q / 10000));
  int fraction = static_cast<int>(q % 10000);
  if (fraction == 0) {
    if (decimal_point) out += '.';
    return;
  }
  out += '.';
  char digits[4];
  for (int k = 3; k >= 0; --k) {
    digits[k] = static_cast<char>('0' + fraction % 10);
    fraction /= 10;
  }
  int n = 4;
  while (n > 0 && digits[n - 1] == '0') --n;
  out.append(digits, static_cast<std::size_t>(n));
}

std::string format_number(double value, bool decimal_point) {
  std::string s;
  append_number(s, value, decimal_point);
  return s;
}

PostedProgram post_action(const ActionProgram& action, const config::Machine& machine, const PostOptions& options) {
  const int number = 1 + (machine.gcode.program_number + action.action - 1) % 9999;
  return generate({&action}, machine, options, number);
}

PostedProgram post_program(const std::vector<ActionProgram>& actions, const config::Machine& machine,
                           const PostOptions& options) {
  std::vector<const ActionProgram*> list;
  for (const auto& a : actions) list.push_back(&a);
  return generate(list, machine, options, machine.gcode.program_number);
}

std::string write_action(const ActionProgram& action, const config::Machine& machine, const PostOptions& options) {
  return post_action(action, machine, options).text();
}

std::string write_program(const std::vector<ActionProgram>& actions, const config::Machine& machine,
                          const PostOptions& options) {
  return post_program(actions, machine, options).text();
}

config::Machine parse_postable_machine(std::string_view yaml_text, const std::string& file_name) {
  config::Machine machine = config::parse_machine(yaml_text, file_name);
  if (const auto problem = posting_problem(machine, machine.gcode.dialect))
    throw config::MachineFileError(
        {config::diagnostic_at(yaml_text, file_name, problem->key, "in the rs274ngc dialect (gcode.dialect), " + problem->message)});
  return machine;
}

config::Machine load_postable_machine(const std::filesystem::path& path) {
  return parse_postable_machine(config::read_machine_text(path), path.string());
}

std::string program_extension(config::Dialect dialect) { return dialect == Dialect::Fanuc ? ".nc" : ".ngc"; }

ProgramFiles write_program_files(const std::filesystem::path& directory, const std::string& name,
                                 const std::vector<ActionProgram>& actions, const config::Machine& machine,
                                 const PostOptions& options) {
  const std::string ext = program_extension(options.dialect.value_or(machine.gcode.dialect));
  std::vector<std::pair<std::filesystem::path, std::string>> files;
  ProgramFiles out;
  out.program = directory / (name + ext);
  files.emplace_back(out.program, write_program(actions, machine, options));
  for (const auto& a : actions) {
    char suffix[32];
    std::snprintf(suffix, sizeof suffix, "-action-%02d", a.action);
    const std::filesystem::path path = directory / (name + suffix + ext);
    files.emplace_back(path, write_action(a, machine, options));
    out.actions.push_back(path);
  }
  write_text_files(files);
  return out;
}

}  // namespace hybridctl::gcode
