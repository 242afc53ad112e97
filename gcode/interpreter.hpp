#pragma once
// The modal G-code interpreter: executes blocks against a machine's model and says what
// the machine does, motion by motion, with the full modal state of each motion.
//
// It is shared by `hybridctl gcode check`, the post-processor's self-check and the
// machine simulator (sim/), which feeds it one line at a time:
//
//   gcode::Interpreter interp(machine, "part.ngc");
//   for each line:  const gcode::LineResult& r = interp.execute_line(text, number);
//                   ... r.motions, r.events ...
//
// A line either executes whole or throws GcodeError ("FILE:line:column: found ...;
// expected ...") and leaves the state as it was, so a caller may report and go on.
//
// Frames: positions are kept in machine coordinates. Program (work) coordinates +
// the active work offset = machine coordinates; G54..G59 take their offsets from the
// machine's setups (config::Setup::work_origin of the setup whose work_offset matches).
// Rotary axes A, B, C are in degrees and are not offset. Tool length offsets (G43 H) are
// accepted and recorded but do not shift positions: hybridctl's coordinates are those
// of the tool tip. The start position is the home position (InterpreterOptions::start).
//
// What it executes: G0 G1 G2 G3 (I J K centre offsets or R), G4 P (dwell, seconds; Fanuc
// machines: X seconds or P milliseconds),
// G17 G18 G19, G20 G21 (inches are converted to mm), G40, G43 H, G49, G53 (with G0/G1),
// G54..G59, G61 G61.1 G64 (accepted, no effect on the model), G80, G90 G91, G90.1 G91.1,
// G94; F S T; M0 M1 M2 M30 M3 M4 M5 M6 M7 M8 M9 M62..M65 P, M67/M68 E Q; the machine
// file's overrides of those M codes (gcode.m_codes) and its heads' deposition codes
// (heads[].codes.on/off). Anything else is an error at its column.

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "config/machine.hpp"
#include "gcode/parser.hpp"
#include "geometry/solid.hpp"

namespace hybridctl::gcode {

using geometry::Vec3;

enum class MotionKind { Rapid, Feed, ArcCw, ArcCcw };
enum class Plane { XY, ZX, YZ };  ///< G17, G18, G19
enum class SpindleState { Off, Cw, Ccw };

/// Rotary axis positions, degrees.
struct Rotary {
  double a = 0, b = 0, c = 0;
  friend bool operator==(const Rotary&, const Rotary&) = default;
};

/// One executed motion and the state it ran in.
struct Motion {
  int line = 0;  ///< source line number
  MotionKind kind = MotionKind::Rapid;
  Vec3 from_work, to_work;           ///< mm, in the work frame of the active offset
  Vec3 from_machine, to_machine;     ///< mm, machine frame
  Rotary from_rotary, to_rotary;     ///< degrees
  Vec3 centre_work, centre_machine;  ///< arcs: the centre (its plane-normal coordinate is the start's)
  Plane plane = Plane::XY;           ///< arcs: the plane of the circle
  double feed = 0;                   ///< mm/min; 0 for rapids (they run at the axes' max_feed)
  int tool = 0;                      ///< the tool (or head) in the spindle; 0 for none
  int work_offset = 54;              ///< 54..59; 53 for a G53 move in machine coordinates
  SpindleState spindle = SpindleState::Off;
  double spindle_speed = 0;  ///< rpm, as last set by S
  bool deposition = false;   ///< a head's deposition is on during this motion
  bool coolant = false;      ///< M7 or M8 in effect

  bool is_arc() const { return kind == MotionKind::ArcCw || kind == MotionKind::ArcCcw; }
};

enum class EventKind {
  ToolChange,     ///< M6: `tool` is the new tool (0: empty)
  SpindleStart,   ///< M3/M4 (or the machine's codes): `value` rpm
  SpindleStop,    ///< M5
  CoolantOn,      ///< M7/M8
  CoolantOff,     ///< M9
  DepositionOn,   ///< a head's on code: `index` = head index, `tool` = its T number
  DepositionOff,  ///< a head's off code
  DigitalOutput,  ///< M62..M65 that is no head's code: `index` = P, `value` 1 on / 0 off
  AnalogOutput,   ///< M67/M68: `index` = E, `value` = Q
  Dwell,          ///< G4: `value` seconds
  WorkOffset,     ///< G54..G59: `index` = 54..59
  ProgramStop,    ///< M0 (or the machine's program_stop): `message` for the operator
  OptionalStop,   ///< M1
  ProgramEnd,     ///< M2/M30 (or the machine's program_end)
};

struct Event {
  int line = 0;
  int column = 0;  ///< of the code that caused it
  EventKind kind = EventKind::ToolChange;
  int tool = 0;
  int index = 0;
  double value = 0;
  bool after_motion = false;  ///< happens after the line's motion (stops and program end)
  std::string message;        ///< stops: the operator message, from the line's or the preceding comment
};

/// What one line did, in order: events with after_motion false, then the motions, then
/// events with after_motion true.
struct LineResult {
  std::vector<Motion> motions;
  std::vector<Event> events;
  void clear() {
    motions.clear();
    events.clear();
  }
};

/// The modal state between lines.
struct ModalState {
  Vec3 position;  ///< machine frame, mm
  Rotary rotary;
  MotionKind motion = MotionKind::Rapid;
  bool motion_active = false;  ///< false after G80 and at the start: axis words need a G0..G3 first
  Plane plane = Plane::XY;
  bool absolute = true;       ///< G90 / G91
  bool arc_absolute = false;  ///< G90.1 / G91.1 (the default: I J K relative to the start)
  bool inches = false;        ///< G20 / G21
  int work_offset = 54;       ///< 54..59
  Vec3 offset;                ///< the active work offset (machine coordinates of work zero)
  double feed = 0;            ///< mm/min
  double spindle_speed = 0;   ///< rpm
  SpindleState spindle = SpindleState::Off;
  int selected_tool = 0;       ///< T
  int tool = 0;                ///< in the spindle (after M6)
  int tool_length_offset = 0;  ///< H of G43; 0 when none (G49)
  bool coolant = false;
  std::uint32_t deposition = 0;  ///< bit i: head i's deposition is on
  bool ended = false;            ///< M2/M30 seen

  bool any_deposition() const { return deposition != 0; }
  Vec3 work_position() const { return {position.x - offset.x, position.y - offset.y, position.z - offset.z}; }
};

/// Tunables, with LinuxCNC-like defaults.
struct InterpreterOptions {
  /// Arc start and end radii may differ by this much (mm) ...
  double arc_radius_tolerance = 0.002;
  /// ... and by this fraction of the radius. Either excess is an error.
  double arc_relative_tolerance = 0.001;
  /// Where the machine starts, machine frame. Default (unset): the home position, X and Y
  /// at the middle of their travel and Z at the top of its travel.
  std::optional<Vec3> start;
};

class Interpreter {
 public:
  /// `machine` must outlive the interpreter. Throws InputError when a head's deposition
  /// codes cannot be recognised (they must be an M code with optional P/E/Q words).
  Interpreter(const config::Machine& machine, std::string file_name = "<gcode>", InterpreterOptions options = {});

  /// Parses and executes one line. The result is valid until the next call. Throws
  /// GcodeError (an InputError) and leaves the state unchanged when the line is wrong.
  const LineResult& execute_line(std::string_view text, int line_number);
  /// Executes a parsed block (same contract).
  const LineResult& execute(const Block& block);

  const ModalState& state() const { return state_; }
  /// Puts the modal state back, e.g. to where it was before a line a controller refused
  /// (an interlock or a soft limit stops the machine before the line's motion).
  void restore(const ModalState& state) { state_ = state; }
  const config::Machine& machine() const { return machine_; }
  const std::string& file_name() const { return parser_.file_name(); }

 private:
  struct HeadCode {
    int m = 0;
    int p = -1;  ///< -1: any (or none)
    int head = 0;
    bool on = false;
  };
  enum class MRole {
    None,
    Stop,
    OptionalStop,
    End,
    SpindleCw,
    SpindleCcw,
    SpindleStop,
    ToolChange,
    CoolantOn,
    CoolantOff
  };

  friend class BlockExecution;  // the steps of run (interpreter_steps.hpp)

  MRole role_of(int m) const;
  [[noreturn]] void fail(const Block& b, int column, const std::string& message) const;
  void run(const Block& b, ModalState& s);

  const config::Machine& machine_;
  Parser parser_;
  InterpreterOptions options_;
  ModalState state_;
  Block block_;
  LineResult result_;
  std::vector<HeadCode> head_codes_;
  std::array<std::pair<int, MRole>, 9> machine_m_codes_{};
  std::string pending_comment_;  ///< the last comment-only line's text, for a following M0
};

/// Every motion and event of a whole program.
struct Program {
  std::vector<Motion> motions;
  std::vector<Event> events;
  int lines = 0;
};

/// Interprets a whole program text; throws GcodeError at the first bad line.
Program interpret(std::string_view text, const config::Machine& machine, std::string file_name = "<gcode>",
                  InterpreterOptions options = {});

std::string_view to_string(MotionKind k);

}  // namespace hybridctl::gcode
