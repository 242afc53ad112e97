#pragma once
// Checks a G-code program against a machine and estimates its cycle time.
//
// check_program() runs the modal interpreter over the text line by line, goes on after a
// bad line (the line is skipped, the state is as before it) and reports:
//   - G-code errors, each at FILE:line:column;
//   - envelope violations: any machine position a motion reaches (end points and, for
//     arcs, the extreme points of the swept circle) outside the envelope's travel, and
//     rotary positions outside their range or on axes the machine lacks;
//   - tool numbers (M6) that are neither a cutting tool nor a head of the machine;
//   - process mistakes: a head's deposition code while the tool in the spindle is not a
//     head, the spindle started while a head is active, feed moves with a cutting tool
//     and the spindle stopped;
//   - the estimated cycle time (time model below).
//
// Time model (docs/gcode.md, "The time model"): the one cycle time every print of a time
// in hybridctl gives. Motion: every move starts and ends at rest (no blending across moves;
// checked against LinuxCNC's trajectory planner by bench/cycle-time-vs-linuxcnc). Along a
// move the speed follows a trapezoid: constant acceleration up to the cruise speed, cruise,
// constant deceleration. The cruise speed is the programmed feed, capped so no axis exceeds
// its max_feed; rapids cruise at the highest speed the axes allow. The acceleration is the
// highest at which no axis exceeds its max_acceleration. On arcs the in-plane limits are
// the lesser of the two plane axes' (the tangent turns through both), and the cruise speed
// is also capped by the centripetal limit v <= sqrt(a * r). Dwells add their time. Changes
// take the machine file's `costs` times, as the planner's estimate counts them: an M6 to
// another tool its tool_change, plus head_switch between a cutting tool and a head; a work
// offset to another setup's its setup_change, or refixture when either setup is re-clamped
// by hand (manual_refixture). Program stops (M0/M1) are counted: their wait is the
// operator's, inside a refixture's time where one follows.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "common/number_text.hpp"
#include "config/machine.hpp"
#include "gcode/interpreter.hpp"

namespace hybridctl::gcode {

/// One problem found, at a line (and column where one applies; 0 otherwise).
struct Finding {
  int line = 0;
  int column = 0;
  std::string message;
};

struct TimeEstimate {
  double total = 0;         ///< s: the cycle time, motion + dwell + changes
  double motion = 0;        ///< s: feed + rapid
  double feed = 0;          ///< s in G1/G2/G3 motions
  double rapid = 0;         ///< s in G0 motions
  double dwell = 0;         ///< s in G4
  double changes = 0;       ///< s: tool changes, head switches, setup changes and refixtures
  double feed_length = 0;   ///< mm travelled at feed (linear axes)
  double rapid_length = 0;  ///< mm travelled at rapid (linear axes)
  int tool_changes = 0;     ///< M6 to another tool (a head is a tool)
  int head_switches = 0;    ///< of those, between a cutting tool and a head
  int setup_changes = 0;    ///< work offset to another setup's, neither re-clamped by hand
  int refixtures = 0;       ///< work offset into or out of a setup re-clamped by hand
  double tool_change_s = 0, head_switch_s = 0, setup_change_s = 0, refixture_s = 0;  ///< their seconds
  int program_stops = 0;    ///< M0/M1 (operator time, not timed)

  /// "16 min 58.7 s: motion 16 min 50.7 s (feed 16 min 23.3 s over 17533.9 mm, rapid 27.4 s
  /// over 2252.7 mm), 1 tool change 8.0 s, 1 refixture 15 min; 1 program stop not timed":
  /// the total and everything it includes.
  std::string str() const;
};

struct CheckReport {
  std::string file;
  int lines = 0;
  int motions = 0, rapids = 0, feeds = 0, arcs = 0;
  std::vector<Finding> errors;    ///< G-code errors; the line was skipped
  std::vector<Finding> envelope;  ///< positions outside the envelope
  std::vector<Finding> tools;     ///< unknown tool numbers
  std::vector<Finding> process;   ///< deposition/spindle misuse
  int errors_not_listed = 0;      ///< beyond CheckOptions::max_listed, per category, summed
  bool program_end = false;       ///< M2/M30 seen
  TimeEstimate time;

  int problems() const {
    return static_cast<int>(errors.size() + envelope.size() + tools.size() + process.size()) + errors_not_listed;
  }
  bool clean() const { return problems() == 0; }
  /// The report as `hybridctl gcode check` prints it.
  std::string str() const;
};

struct CheckOptions {
  double envelope_tolerance = 1e-6;  ///< mm (deg) beyond the travel still counted inside
  std::size_t max_listed = 100;      ///< per category; the rest are counted
  InterpreterOptions interpreter;
};

/// Checks `text` (a whole program) against `machine`; never throws for bad G-code.
CheckReport check_program(std::string_view text, const config::Machine& machine, std::string file_name,
                          const CheckOptions& options = {});

/// The machine-frame bounding box of a motion: its end points and, for arcs, the extreme
/// points of the circle within the swept angle.
void motion_bounds(const Motion& m, Vec3& lo, Vec3& hi);

/// What a motion reaches outside the envelope, as text ("X reaches 412.5, beyond the X
/// travel [0, 400]"), or nothing when it stays inside (within `tolerance`). What it reaches
/// is its end point and an arc's extreme points; its start is the previous motion's end.
std::optional<std::string> envelope_violation(const Motion& m, const config::Envelope& envelope,
                                              double tolerance = 1e-6);

/// Seconds one motion takes under the time model above.
double motion_time(const Motion& m, const config::Envelope& envelope);

/// The swept angle of an arc, radians, > 0 (2 pi for a full circle).
double arc_sweep(const Motion& m);

/// "3 min 12.4 s", "12.4 s", "1 h 02 min 03 s" (common/number_text.hpp).
using hybridctl::format_duration;

}  // namespace hybridctl::gcode
