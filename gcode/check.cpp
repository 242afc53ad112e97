#include "gcode/check.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "common/number_text.hpp"

namespace hybridctl::gcode {

namespace {

constexpr double kTwoPi = 2.0 * M_PI;
constexpr double kFullCircle = 1e-9;  ///< mm: start and end this close make a full circle

std::string fmt(double v) { return trimmed_number(v, 4); }

double get(const Vec3& v, int axis) { return axis == 0 ? v.x : axis == 1 ? v.y : v.z; }
double& get(Vec3& v, int axis) { return axis == 0 ? v.x : axis == 1 ? v.y : v.z; }

struct PlaneAxes {
  int first, second, normal;
};
PlaneAxes plane_axes(Plane p) {
  switch (p) {
    case Plane::XY: return {0, 1, 2};
    case Plane::ZX: return {2, 0, 1};
    case Plane::YZ: return {1, 2, 0};
  }
  return {0, 1, 2};
}

const config::LinearAxis& linear(const config::Envelope& e, int axis) {
  return axis == 0 ? e.x : axis == 1 ? e.y : e.z;
}

/// Time to travel distance `d` from rest to rest with cruise speed v and acceleration a.
double trapezoid(double d, double v, double a) {
  if (d <= 0 || v <= 0 || a <= 0) return 0;
  if (d * a >= v * v) return d / v + v / a;
  return 2.0 * std::sqrt(d / a);
}

void add(std::vector<Finding>& list, int& not_listed, std::size_t max, Finding f) {
  if (list.size() < max)
    list.push_back(std::move(f));
  else
    ++not_listed;
}

}  // namespace

double arc_sweep(const Motion& m) {
  const PlaneAxes pa = plane_axes(m.plane);
  const double a0 = std::atan2(get(m.from_machine, pa.second) - get(m.centre_machine, pa.second),
                               get(m.from_machine, pa.first) - get(m.centre_machine, pa.first));
  const double a1 = std::atan2(get(m.to_machine, pa.second) - get(m.centre_machine, pa.second),
                               get(m.to_machine, pa.first) - get(m.centre_machine, pa.first));
  const double chord = std::hypot(get(m.to_machine, pa.first) - get(m.from_machine, pa.first),
                                  get(m.to_machine, pa.second) - get(m.from_machine, pa.second));
  if (chord < kFullCircle) return kTwoPi;
  double sweep = m.kind == MotionKind::ArcCcw ? a1 - a0 : a0 - a1;
  while (sweep <= 0) sweep += kTwoPi;
  while (sweep > kTwoPi) sweep -= kTwoPi;
  return sweep;
}

namespace {

/// The box of the points a motion reaches: its end point and, for arcs, the circle's
/// extreme points within the sweep. `lo`/`hi` come in holding the points so far.
void add_reach(const Motion& m, Vec3& lo, Vec3& hi) {
  if (!m.is_arc()) return;
  const PlaneAxes pa = plane_axes(m.plane);
  const double cx = get(m.centre_machine, pa.first), cy = get(m.centre_machine, pa.second);
  const double r = std::hypot(get(m.from_machine, pa.first) - cx, get(m.from_machine, pa.second) - cy);
  const double start = std::atan2(get(m.from_machine, pa.second) - cy, get(m.from_machine, pa.first) - cx);
  const double sweep = arc_sweep(m);
  const bool ccw = m.kind == MotionKind::ArcCcw;
  // The circle's extreme points at 0, 90, 180 and 270 degrees, where the sweep covers them.
  for (int k = 0; k < 4; ++k) {
    const double angle = k * M_PI_2;
    double delta = ccw ? angle - start : start - angle;
    while (delta < 0) delta += kTwoPi;
    while (delta >= kTwoPi) delta -= kTwoPi;
    if (delta > sweep) continue;
    const double x = cx + r * std::cos(angle), y = cy + r * std::sin(angle);
    get(lo, pa.first) = std::min(get(lo, pa.first), x);
    get(hi, pa.first) = std::max(get(hi, pa.first), x);
    get(lo, pa.second) = std::min(get(lo, pa.second), y);
    get(hi, pa.second) = std::max(get(hi, pa.second), y);
  }
}

}  // namespace

void motion_bounds(const Motion& m, Vec3& lo, Vec3& hi) {
  lo = {std::min(m.from_machine.x, m.to_machine.x), std::min(m.from_machine.y, m.to_machine.y),
        std::min(m.from_machine.z, m.to_machine.z)};
  hi = {std::max(m.from_machine.x, m.to_machine.x), std::max(m.from_machine.y, m.to_machine.y),
        std::max(m.from_machine.z, m.to_machine.z)};
  add_reach(m, lo, hi);
}

std::optional<std::string> envelope_violation(const Motion& m, const config::Envelope& envelope, double tolerance) {
  // The start is the previous motion's end, checked with it: only what this motion
  // reaches is reported here.
  Vec3 lo = m.to_machine, hi = m.to_machine;
  add_reach(m, lo, hi);
  std::string out;
  const char names[3] = {'X', 'Y', 'Z'};
  for (int axis = 0; axis < 3; ++axis) {
    const config::Range& t = linear(envelope, axis).travel;
    const bool below = get(lo, axis)<t.min - tolerance, beyond = get(hi, axis)> t.max + tolerance;
    if (!below && !beyond) continue;  // the common case: no text built
    const std::string travel = std::string(1, names[axis]) + " travel [" + fmt(t.min) + ", " + fmt(t.max) + "]";
    if (below)
      out += std::string(out.empty() ? "" : "; ") + names[axis] + " reaches " + fmt(get(lo, axis)) + ", below the " +
             travel;
    if (beyond)
      out += std::string(out.empty() ? "" : "; ") + names[axis] + " reaches " + fmt(get(hi, axis)) + ", beyond the " +
             travel;
  }
  const std::pair<char, std::pair<double, double>> rotary[3] = {{'A', {m.from_rotary.a, m.to_rotary.a}},
                                                                {'B', {m.from_rotary.b, m.to_rotary.b}},
                                                                {'C', {m.from_rotary.c, m.to_rotary.c}}};
  for (const auto& [name, positions] : rotary) {
    const config::RotaryAxis* axis = envelope.find_rotary(name);
    if (!axis) {
      if (positions.first != positions.second)
        out += std::string(out.empty() ? "" : "; ") + name + " moves to " + fmt(positions.second) +
               " but the machine has no " + name + " axis";
      continue;
    }
    const double v = positions.second;
    if (v < axis->range.min - tolerance || v > axis->range.max + tolerance)
      out += std::string(out.empty() ? "" : "; ") + name + " reaches " + fmt(v) + " deg, outside the " + name +
             " range [" + fmt(axis->range.min) + ", " + fmt(axis->range.max) + "]";
  }
  if (out.empty()) return std::nullopt;
  return out;
}

double motion_time(const Motion& m, const config::Envelope& envelope) {
  const config::RotaryAxis default_rotary;
  const auto rotary_axis = [&](char name) -> const config::RotaryAxis& {
    const config::RotaryAxis* a = envelope.find_rotary(name);
    return a ? *a : default_rotary;
  };
  // The motion is parametrised by u in [0, 1]; each limit caps du/dt and d2u/dt2.
  double u_speed = INFINITY, u_accel = INFINITY;
  const auto limit = [&](double extent, double max_feed_per_min, double max_accel) {
    if (extent <= 0) return;
    u_speed = std::min(u_speed, max_feed_per_min / 60.0 / extent);
    u_accel = std::min(u_accel, max_accel / extent);
  };
  const double rotary_delta[3] = {std::abs(m.to_rotary.a - m.from_rotary.a), std::abs(m.to_rotary.b - m.from_rotary.b),
                                  std::abs(m.to_rotary.c - m.from_rotary.c)};
  double rotary_length = 0;
  for (int k = 0; k < 3; ++k) {
    const config::RotaryAxis& axis = rotary_axis("ABC"[k]);
    limit(rotary_delta[k], axis.max_feed, axis.max_acceleration);
    rotary_length = std::max(rotary_length, rotary_delta[k]);
  }
  double length = 0;  // linear path length
  if (m.is_arc()) {
    const PlaneAxes pa = plane_axes(m.plane);
    const double r = std::hypot(get(m.from_machine, pa.first) - get(m.centre_machine, pa.first),
                                get(m.from_machine, pa.second) - get(m.centre_machine, pa.second));
    const double arc = r * arc_sweep(m);
    const double h = std::abs(get(m.to_machine, pa.normal) - get(m.from_machine, pa.normal));
    length = std::hypot(arc, h);
    const config::LinearAxis& a1 = linear(envelope, pa.first);
    const config::LinearAxis& a2 = linear(envelope, pa.second);
    const double plane_feed = std::min(a1.max_feed, a2.max_feed);
    const double plane_accel = std::min(a1.max_acceleration, a2.max_acceleration);
    limit(arc, plane_feed, plane_accel);
    // Centripetal: v^2 / r <= a.
    if (arc > 0) u_speed = std::min(u_speed, std::sqrt(plane_accel * r) / arc);
    const config::LinearAxis& n = linear(envelope, pa.normal);
    limit(h, n.max_feed, n.max_acceleration);
  } else {
    const double d[3] = {std::abs(m.to_machine.x - m.from_machine.x), std::abs(m.to_machine.y - m.from_machine.y),
                         std::abs(m.to_machine.z - m.from_machine.z)};
    length = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    for (int axis = 0; axis < 3; ++axis)
      limit(d[axis], linear(envelope, axis).max_feed, linear(envelope, axis).max_acceleration);
  }
  if (m.kind != MotionKind::Rapid && m.feed > 0) {
    // F is along the linear path; for rotary-only moves it is in deg/min.
    const double extent = length > 0 ? length : rotary_length;
    if (extent > 0) u_speed = std::min(u_speed, m.feed / 60.0 / extent);
  }
  if (!std::isfinite(u_speed) || !std::isfinite(u_accel)) return 0;  // no movement
  return trapezoid(1.0, u_speed, u_accel);
}

namespace {

/// One program's check: the report it fills, and what one line's events and motions add.
class ProgramCheck {
 public:
  ProgramCheck(CheckReport& report, const config::Machine& machine, const CheckOptions& options)
      : report_(report), machine_(machine), options_(options) {}

  void add_error(Finding f) { finding(report_.errors, std::move(f)); }
  void event(const Event& e, const ModalState& after);
  void motion(const Motion& m);

 private:
  void finding(std::vector<Finding>& list, Finding f) {
    add(list, report_.errors_not_listed, options_.max_listed, std::move(f));
  }
  std::string tool_name(int number) const;
  void unknown_tool(const Event& e);

  void tool_change(int tool);
  void work_offset(int offset);

  CheckReport& report_;
  const config::Machine& machine_;
  const CheckOptions& options_;
  bool warned_spindle_stopped_ = false;  // one finding per run of feed moves with the spindle stopped
  int tool_ = 0;                         // in the spindle: 0 until the first M6
  int work_offset_ = 0;                  // 54..59; 0 until the program selects one
};

// The changes at the machine file's costs, as the planner's estimate counts them
// (planner/costing/costs.cpp, change_between).
void ProgramCheck::tool_change(int tool) {
  if (tool == tool_) return;
  const bool head_before = machine_.find_head_by_tool(tool_) != nullptr;
  const bool head_after = machine_.find_head_by_tool(tool) != nullptr;
  const bool loaded_before = tool_ != 0;
  tool_ = tool;
  TimeEstimate& t = report_.time;
  ++t.tool_changes;
  t.tool_change_s += machine_.costs.tool_change;
  if (loaded_before && head_before != head_after) {
    ++t.head_switches;
    t.head_switch_s += machine_.costs.head_switch;
  }
}

void ProgramCheck::work_offset(int offset) {
  const int before = work_offset_;
  work_offset_ = offset;
  if (before == 0 || before == offset) return;
  const config::Setup* from = machine_.find_setup_by_work_offset(before);
  const config::Setup* to = machine_.find_setup_by_work_offset(offset);
  TimeEstimate& t = report_.time;
  if ((from && from->manual_refixture) || (to && to->manual_refixture)) {
    ++t.refixtures;
    t.refixture_s += machine_.costs.refixture * 60.0;
  } else {
    ++t.setup_changes;
    t.setup_change_s += machine_.costs.setup_change;
  }
}

std::string ProgramCheck::tool_name(int number) const {
  if (const config::CuttingTool* t = machine_.find_tool(number))
    return "T" + std::to_string(number) + " (" + t->name + ")";
  if (const config::AdditiveHead* h = machine_.find_head_by_tool(number))
    return "T" + std::to_string(number) + " (head " + h->name + ")";
  return "T" + std::to_string(number);
}

void ProgramCheck::unknown_tool(const Event& e) {
  std::string known;
  for (const auto& t : machine_.tools) known += (known.empty() ? "" : ", ") + std::string("T") + std::to_string(t.number);
  for (const auto& h : machine_.heads)
    known += (known.empty() ? "" : ", ") + std::string("T") + std::to_string(h.tool_number) + " (" + h.name + ")";
  finding(report_.tools, Finding{e.line, e.column,
                                 "T" + std::to_string(e.tool) + " is neither a cutting tool nor a head of machine '" +
                                     machine_.name + "'; expected one of " + known});
}

void ProgramCheck::event(const Event& e, const ModalState& after) {
  const bool head_active_after = machine_.find_head_by_tool(after.tool) != nullptr;
  switch (e.kind) {
    case EventKind::ToolChange:
      tool_change(e.tool);
      if (e.tool != 0 && !machine_.find_tool(e.tool) && !machine_.find_head_by_tool(e.tool)) unknown_tool(e);
      break;
    case EventKind::WorkOffset: work_offset(e.index); break;
    case EventKind::DepositionOn:
      if (!head_active_after)
        finding(report_.process,
                Finding{e.line, e.column,
                        "deposition on for head '" + machine_.heads[static_cast<std::size_t>(e.index)].name +
                            "' while " + (after.tool == 0 ? std::string("no tool") : tool_name(after.tool)) +
                            " is in the spindle; expected the head selected first (T" + std::to_string(e.tool) + " " +
                            machine_.gcode.m_codes.tool_change + ")"});
      break;
    case EventKind::SpindleStart:
      if (head_active_after)
        finding(report_.process, Finding{e.line, e.column,
                                         "spindle started while " + tool_name(after.tool) +
                                             " is active; expected a cutting tool in the spindle"});
      break;
    case EventKind::Dwell: report_.time.dwell += e.value; break;
    case EventKind::ProgramStop:
    case EventKind::OptionalStop: ++report_.time.program_stops; break;
    case EventKind::ProgramEnd: report_.program_end = true; break;
    default: break;
  }
}

/// The path length of a motion, mm: an arc's (a helix's) or a straight line's.
double motion_length(const Motion& m) {
  if (m.is_arc()) {
    const PlaneAxes pa = plane_axes(m.plane);
    const double r = std::hypot(get(m.from_machine, pa.first) - get(m.centre_machine, pa.first),
                                get(m.from_machine, pa.second) - get(m.centre_machine, pa.second));
    return std::hypot(r * arc_sweep(m), get(m.to_machine, pa.normal) - get(m.from_machine, pa.normal));
  }
  return std::hypot(m.to_machine.x - m.from_machine.x, m.to_machine.y - m.from_machine.y,
                    m.to_machine.z - m.from_machine.z);
}

void ProgramCheck::motion(const Motion& m) {
  ++report_.motions;
  if (m.kind == MotionKind::Rapid)
    ++report_.rapids;
  else if (m.kind == MotionKind::Feed)
    ++report_.feeds;
  else
    ++report_.arcs;
  if (auto v = envelope_violation(m, machine_.envelope, options_.envelope_tolerance))
    finding(report_.envelope, Finding{m.line, 0, *v});
  const double t = motion_time(m, machine_.envelope);
  const double length = motion_length(m);
  if (m.kind == MotionKind::Rapid) {
    report_.time.rapid += t;
    report_.time.rapid_length += length;
    return;
  }
  report_.time.feed += t;
  report_.time.feed_length += length;
  const bool cutting_tool = machine_.find_tool(m.tool) != nullptr;
  if (cutting_tool && m.spindle == SpindleState::Off) {
    if (!warned_spindle_stopped_)
      finding(report_.process, Finding{m.line, 0,
                                       "feed move with " + tool_name(m.tool) +
                                           " and the spindle stopped; expected the spindle started (" +
                                           machine_.gcode.m_codes.spindle_cw + ") before cutting"});
    warned_spindle_stopped_ = true;
  } else {
    warned_spindle_stopped_ = false;
  }
}

}  // namespace

CheckReport check_program(std::string_view text, const config::Machine& machine, std::string file_name,
                          const CheckOptions& options) {
  CheckReport report;
  report.file = file_name;
  Interpreter interpreter(machine, file_name, options.interpreter);
  ProgramCheck check(report, machine, options);
  for_each_line(text, [&](std::string_view line, int number) {
    report.lines = number;
    const LineResult* result = nullptr;
    try {
      result = &interpreter.execute_line(line, number);
    } catch (const GcodeError& e) {
      check.add_error(Finding{e.line(), e.column(), e.message()});
      return;
    }
    for (const Event& e : result->events) check.event(e, interpreter.state());
    for (const Motion& m : result->motions) check.motion(m);
  });
  if (!report.program_end)
    check.add_error(Finding{report.lines, 0,
                            "the program has no end; expected " + machine.gcode.m_codes.program_end +
                                " (or M2/M30) as its last code, as LinuxCNC requires"});
  TimeEstimate& t = report.time;
  t.motion = t.feed + t.rapid;
  t.changes = t.tool_change_s + t.head_switch_s + t.setup_change_s + t.refixture_s;
  t.total = t.motion + t.dwell + t.changes;
  return report;
}

std::string CheckReport::str() const {
  std::string out = file + ": " + std::to_string(lines) + " lines, " + std::to_string(motions) + " moves (" +
                    std::to_string(rapids) + " rapid, " + std::to_string(feeds) + " feed, " + std::to_string(arcs) +
                    " arc)\n";
  for (const Finding& f : errors) {
    out += file + ":" + std::to_string(f.line);
    if (f.column > 0) out += ":" + std::to_string(f.column);
    out += ": error: " + f.message + "\n";
  }
  for (const Finding& f : envelope)
    out += file + ":" + std::to_string(f.line) + ": outside the envelope: " + f.message + "\n";
  for (const Finding& f : tools)
    out += file + ":" + std::to_string(f.line) + ":" + std::to_string(f.column) + ": unknown tool: " + f.message + "\n";
  for (const Finding& f : process) {
    out += file + ":" + std::to_string(f.line);
    if (f.column > 0) out += ":" + std::to_string(f.column);
    out += ": process: " + f.message + "\n";
  }
  if (errors_not_listed > 0) out += "... and " + std::to_string(errors_not_listed) + " more problems not listed\n";
  out += "cycle time: " + time.str() + "\n";
  const int n = problems();
  out += file + ": " + (n == 0 ? std::string("clean") : std::to_string(n) + (n == 1 ? " problem" : " problems")) + "\n";
  return out;
}

namespace {

std::string counted(int n, const std::string& one, const std::string& many, double seconds) {
  return std::to_string(n) + " " + (n == 1 ? one : many) + " " + format_duration(seconds);
}

}  // namespace

std::string TimeEstimate::str() const {
  std::string out = format_duration(total) + ": motion " + format_duration(motion) + " (feed " + format_duration(feed) +
                    " over " + trimmed_number(feed_length, 1) + " mm, rapid " + format_duration(rapid) + " over " +
                    trimmed_number(rapid_length, 1) + " mm; every move from rest to rest)";
  if (dwell > 0) out += ", dwell " + format_duration(dwell);
  if (tool_changes > 0) out += ", " + counted(tool_changes, "tool change", "tool changes", tool_change_s);
  if (head_switches > 0) out += ", " + counted(head_switches, "head switch", "head switches", head_switch_s);
  if (setup_changes > 0) out += ", " + counted(setup_changes, "setup change", "setup changes", setup_change_s);
  if (refixtures > 0) out += ", " + counted(refixtures, "refixture", "refixtures", refixture_s);
  if (program_stops > 0)
    out += "; " + std::to_string(program_stops) + " program stop" + (program_stops == 1 ? "" : "s") +
           " not timed (the operator's; a refixture's time holds its wait)";
  return out;
}

}  // namespace hybridctl::gcode

