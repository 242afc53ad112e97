// The interpreter's shell: setup from the machine file, line and block entry points, and
// the order of a block's steps (Interpreter::run). The steps themselves are in
// interpreter_modal.cpp (codes, modes, M-code actions, dwell, stops) and
// interpreter_motion.cpp (G0..G3, G53, arc centres).
#include "gcode/interpreter.hpp"

#include <cmath>
#include <cstdio>

#include "common/number_text.hpp"
#include "gcode/interpreter_steps.hpp"

namespace hybridctl::gcode {

namespace detail {

/// T, H, P (output) and E (analog output) numbers are whole numbers from 0 to this.
constexpr double kMaxNumberWord = 99999;

bool number_word(double v) { return v >= 0 && v <= kMaxNumberWord && v == std::nearbyint(v); }

std::string fmt(double v) { return trimmed_number(v, 4); }

}  // namespace detail

namespace {

using detail::bit;
using detail::number_word;

constexpr int kMaxHeads = 32;

int m_number(const std::string& code) { return std::atoi(code.c_str() + 1); }

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

// A block runs in the order of LinuxCNC's execute_block (rs274ngc/interp_execute.cc),
// except that the units come before F (they scale it). One step, one function
// (BlockExecution, interpreter_steps.hpp):
//
//   step                       codes and words          result
//   refuse_words_after_end     anything after M2/M30    error
//   group_g_codes              G codes by modal group   errors: unknown, two of a group
//   classify_m_codes           M codes: role or head    errors: unknown, two of a group
//   set_units                  G20 G21
//   set_feed                   F                        mm/min
//   set_spindle_speed          S                        rpm
//   select_tool                T
//   change_tool                M6                       event ToolChange
//   switch_spindle             M3 M4 M5                 events SpindleStart/Stop
//   switch_coolant             M7 M8 M9                 events CoolantOn/Off
//   switch_outputs             heads' codes, M62..M68   events Deposition*, *Output
//   dwell                      G4 P (Fanuc X/P)         event Dwell
//   set_plane                  G17 G18 G19
//   set_length_offset          G43 H, G49
//   set_work_offset            G54..G59                 event WorkOffset
//   set_distance_modes         G90 G91, G90.1 G91.1
//   move                       G0..G3, G53, G80, axes   the motion
//   refuse_unused_words        words no code used       error
//   stop_or_end                M0 M1, M2 M30            events after the motion
//
// G40, G61, G61.1, G64 and G94 are accepted (grouped) and change nothing in the model.
void Interpreter::run(const Block& b, ModalState& s) {
  if (b.no_words()) return;
  if (b.program_number >= 0) return;  // a Fanuc O line: the parser allows nothing else on it
  BlockExecution block(*this, b, s);
  block.refuse_words_after_end();
  block.group_g_codes();
  block.classify_m_codes();
  block.set_units();
  block.set_feed();
  block.set_spindle_speed();
  block.select_tool();
  block.change_tool();
  block.switch_spindle();
  block.switch_coolant();
  block.switch_outputs();
  block.dwell();
  block.set_plane();
  block.set_length_offset();
  block.set_work_offset();
  block.set_distance_modes();
  block.move();
  block.refuse_unused_words();
  block.stop_or_end();
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
