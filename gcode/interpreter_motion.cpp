// The motion step of a block: the motion mode (G0..G3, G80), G53's checks, the end point
// from the axis words, the feed, and an arc's centre from R or from I J K offsets.
#include <algorithm>
#include <cmath>

#include "gcode/interpreter_steps.hpp"

namespace hybridctl::gcode {

namespace {

using detail::bit;
using detail::fmt;
using detail::kArcLetters;
using detail::kAxisLetters;

/// LinuxCNC's RADIUS_TOLERANCE_MM: an R arc may miss reaching its end by this much, and
/// centre-format radii below it are zero.
constexpr double kRadiusTolerance = 0.00127;
constexpr char kLinearAxes[3] = {'X', 'Y', 'Z'};

double& at(Vec3& v, int axis) { return axis == 0 ? v.x : axis == 1 ? v.y : v.z; }
double at(const Vec3& v, int axis) { return axis == 0 ? v.x : axis == 1 ? v.y : v.z; }

Vec3 minus(const Vec3& a, const Vec3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }

/// The in-plane axes (first, second) and the normal of a plane, as 0 = X, 1 = Y, 2 = Z.
struct PlaneAxes {
  int first, second, normal;
  char first_offset, second_offset;  // I J K letters of the in-plane axes
  const char* name;
  const char* axes;

  std::uint32_t offset_letters() const { return bit(first_offset) | bit(second_offset); }
};
PlaneAxes axes_of(Plane p) {
  switch (p) {
    case Plane::XY: return {0, 1, 2, 'I', 'J', "XY", "X or Y"};
    case Plane::ZX: return {2, 0, 1, 'K', 'I', "ZX", "Z or X"};
    case Plane::YZ: return {1, 2, 0, 'J', 'K', "YZ", "Y or Z"};
  }
  return {0, 1, 2, 'I', 'J', "XY", "X or Y"};
}

const char* code_of(MotionKind kind) {
  return kind == MotionKind::Feed ? "G1" : kind == MotionKind::ArcCw ? "G2" : "G3";
}

}  // namespace

void BlockExecution::move() {
  set_motion_mode();
  const std::uint32_t axis_words = b_.letters & kAxisLetters & ~dwell_letters_;
  int first_axis_column = 0;
  for (char L : {'X', 'Y', 'Z', 'A', 'B', 'C'})
    if ((axis_words & bit(L)) && (first_axis_column == 0 || b_.column(L) < first_axis_column))
      first_axis_column = b_.column(L);
  check_machine_coordinates();
  if (axis_words != 0 || (arc_mode() && (b_.letters & kArcLetters) != 0)) {
    if (!s_.motion_active)
      fail(first_axis_column,
           "found axis words with no motion mode in effect; expected G0, G1, G2 or G3 on "
           "this or an earlier line");
    used_ |= axis_words;
    in_.result_.motions.push_back(straight_or_arc(first_axis_column));
  } else if (g_[kMachineCoords].code >= 0) {
    fail(g_[kMachineCoords].column, "found G53 with no axis words; expected the machine coordinates to move to");
  }
}

void BlockExecution::set_motion_mode() {
  const int code = g_[kMotion].code;
  if (code < 0) return;
  s_.motion_active = code != 800;
  if (s_.motion_active)
    s_.motion = code == 0    ? MotionKind::Rapid
                : code == 10 ? MotionKind::Feed
                : code == 20 ? MotionKind::ArcCw
                             : MotionKind::ArcCcw;
}

// LinuxCNC runs a G2/G3 with centre offsets and no axis words as a full circle.
bool BlockExecution::arc_mode() const {
  return s_.motion_active && (s_.motion == MotionKind::ArcCw || s_.motion == MotionKind::ArcCcw);
}

void BlockExecution::check_machine_coordinates() const {
  const Slot& g53 = g_[kMachineCoords];
  if (g53.code < 0) return;
  if (!s_.motion_active || (s_.motion != MotionKind::Rapid && s_.motion != MotionKind::Feed))
    fail(g53.column,
         "found G53 without G0 or G1; expected G53 G0 or G53 G1 (machine coordinates "
         "apply to straight moves only)");
  if (!s_.absolute)
    fail(g53.column,
         "found G53 in incremental mode (G91); expected G90 for moves in machine "
         "coordinates");
}

Motion BlockExecution::straight_or_arc(int first_axis_column) {
  Motion m;
  m.line = b_.line;
  m.kind = s_.motion;
  m.from_machine = s_.position;
  m.from_rotary = s_.rotary;
  target(m);
  const int column = motion_column(first_axis_column);
  if (m.kind != MotionKind::Rapid) {
    if (s_.feed <= 0)
      fail(column, "found " + std::string(code_of(m.kind)) +
                       " with zero feed rate; expected an F word greater than 0 on this or an earlier line");
    m.feed = s_.feed;
  }
  if (m.is_arc()) arc_centre(m, column);
  m.from_work = minus(m.from_machine, s_.offset);
  m.to_work = minus(m.to_machine, s_.offset);
  m.tool = s_.tool;
  m.work_offset = g_[kMachineCoords].code >= 0 ? 53 : s_.work_offset;
  m.spindle = s_.spindle;
  m.spindle_speed = s_.spindle_speed;
  m.deposition = s_.any_deposition();
  m.coolant = s_.coolant;
  s_.position = m.to_machine;
  s_.rotary = m.to_rotary;
  return m;
}

// The end point: work coordinates (absolute or incremental) or, with G53, machine
// coordinates; rotary axes in degrees, not offset.
void BlockExecution::target(Motion& m) const {
  const bool machine_coords = g_[kMachineCoords].code >= 0;
  Vec3 to = s_.position;
  Rotary rot = s_.rotary;
  for (int axis = 0; axis < 3; ++axis) {
    const char L = kLinearAxes[axis];
    if (!b_.has(L)) continue;
    const double v = b_.value(L) * unit_;
    if (machine_coords)
      at(to, axis) = v;
    else
      at(to, axis) = s_.absolute ? at(s_.offset, axis) + v : at(s_.position, axis) + v;
  }
  if (b_.has('A')) rot.a = s_.absolute || machine_coords ? b_.value('A') : rot.a + b_.value('A');
  if (b_.has('B')) rot.b = s_.absolute || machine_coords ? b_.value('B') : rot.b + b_.value('B');
  if (b_.has('C')) rot.c = s_.absolute || machine_coords ? b_.value('C') : rot.c + b_.value('C');
  m.to_machine = to;
  m.to_rotary = rot;
}

// The column an error about the motion points at: its G code, or with none on the line
// its first axis word; a modal G2/G3 line may hold only arc words (a full circle: I J K;
// or R), then the first of those.
int BlockExecution::motion_column(int first_axis_column) const {
  if (g_[kMotion].code >= 0) return g_[kMotion].column;
  int column = first_axis_column;
  if (arc_mode() && column == 0)
    for (char L : {'I', 'J', 'K', 'R'})
      if (b_.has(L) && (column == 0 || b_.column(L) < column)) column = b_.column(L);
  return column;
}

void BlockExecution::arc_centre(Motion& m, int column) {
  const PlaneAxes pa = axes_of(s_.plane);
  for (char L : {'I', 'J', 'K'})
    if (b_.has(L) && !(pa.offset_letters() & bit(L)))
      fail(b_.column(L), "found " + std::string(1, L) + " with " + code_of(m.kind) + " in the " + pa.name +
                             " plane; expected only " + pa.first_offset + " and " + pa.second_offset +
                             " (or R) for arcs in that plane");
  const std::array<double, 2> c = b_.has('R') ? centre_from_radius(m, column) : centre_from_offsets(m, column);
  Vec3 centre = s_.position;
  at(centre, pa.first) = c[0];
  at(centre, pa.second) = c[1];
  m.centre_machine = centre;
  m.centre_work = minus(centre, s_.offset);
  m.plane = s_.plane;
}

std::array<double, 2> BlockExecution::centre_from_radius(const Motion& m, int column) {
  const PlaneAxes pa = axes_of(s_.plane);
  const double x0 = at(m.from_machine, pa.first), y0 = at(m.from_machine, pa.second);
  const double x1 = at(m.to_machine, pa.first), y1 = at(m.to_machine, pa.second);
  if (b_.letters & kArcLetters & pa.offset_letters())
    fail(b_.column('R'), std::string("found R with ") + pa.first_offset + "/" + pa.second_offset +
                             " offsets; expected either a radius R or centre offsets, not both");
  if (!b_.has(kLinearAxes[pa.first]) && !b_.has(kLinearAxes[pa.second]))
    fail(column, "found " + std::string(code_of(m.kind)) + " with R and no " + pa.axes +
                     " word; expected the arc's end point in the " + pa.name +
                     " plane (an R arc cannot be a full circle)");
  const double radius = b_.value('R') * unit_;
  if (x0 == x1 && y0 == y1)
    fail(b_.column('R'),
         "found an R arc that ends where it starts; expected a different end point (use I/J "
         "offsets for a full circle)");
  const double abs_radius = std::abs(radius);
  const double mx = 0.5 * (x0 + x1), my = 0.5 * (y0 + y1);
  double half = std::hypot(x1 - mx, y1 - my);
  if (half - abs_radius > kRadiusTolerance)
    fail(b_.column('R'), "found R" + fmt(b_.value('R')) + ", too small to reach the end point (half the chord is " +
                             fmt(half / unit_) + "); expected a radius of at least " + fmt(half / unit_));
  if (half / abs_radius > 1 - 1e-12) half = abs_radius;
  const bool cw = m.kind == MotionKind::ArcCw;
  double theta = std::atan2(y1 - y0, x1 - x0) + ((cw && radius > 0) || (!cw && radius < 0) ? -M_PI_2 : M_PI_2);
  const double offset = abs_radius * std::cos(std::asin(half / abs_radius));
  used_ |= bit('R');
  return {mx + offset * std::cos(theta), my + offset * std::sin(theta)};
}

std::array<double, 2> BlockExecution::centre_from_offsets(const Motion& m, int column) {
  const PlaneAxes pa = axes_of(s_.plane);
  const double x0 = at(m.from_machine, pa.first), y0 = at(m.from_machine, pa.second);
  const double x1 = at(m.to_machine, pa.first), y1 = at(m.to_machine, pa.second);
  const std::uint32_t offsets = b_.letters & kArcLetters & pa.offset_letters();
  if (!offsets)
    fail(column, "found " + std::string(code_of(m.kind)) + " with no " + pa.first_offset + ", " + pa.second_offset +
                     " or R; expected the centre as " + pa.first_offset + "/" + pa.second_offset +
                     " offsets or a radius R");
  const double i = b_.has(pa.first_offset) ? b_.value(pa.first_offset) * unit_ : 0.0;
  const double j = b_.has(pa.second_offset) ? b_.value(pa.second_offset) * unit_ : 0.0;
  const double cx = s_.arc_absolute ? at(s_.offset, pa.first) + i : x0 + i;
  const double cy = s_.arc_absolute ? at(s_.offset, pa.second) + j : y0 + j;
  const double r0 = std::hypot(x0 - cx, y0 - cy), r1 = std::hypot(x1 - cx, y1 - cy);
  const int offset_column = b_.has(pa.first_offset) ? b_.column(pa.first_offset) : b_.column(pa.second_offset);
  if (r0 < kRadiusTolerance || r1 < kRadiusTolerance)
    fail(offset_column, "found an arc of zero radius (start radius " + fmt(r0 / unit_) + ", end radius " +
                            fmt(r1 / unit_) + "); expected the centre away from the start and end points");
  const double abs_err = std::abs(r0 - r1);
  const double rel_err = abs_err / std::max(r0, r1);
  const InterpreterOptions& options = in_.options_;
  if (abs_err > options.arc_radius_tolerance || rel_err > options.arc_relative_tolerance)
    fail(offset_column, "radius to end of arc differs from radius to start: start radius " + fmt(r0 / unit_) +
                            ", end radius " + fmt(r1 / unit_) + " (difference " + fmt(abs_err / unit_) +
                            "); expected them equal within " + fmt(options.arc_radius_tolerance) + " mm and " +
                            fmt(options.arc_relative_tolerance * 100) + " %");
  used_ |= offsets;
  return {cx, cy};
}

}  // namespace hybridctl::gcode
