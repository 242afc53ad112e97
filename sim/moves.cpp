#include "sim/moves.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace hybridctl::sim {
namespace {

// An arc never has more chords than this (a 1 m radius at 1 um tolerance needs ~2200).
constexpr double kMaxChords = 1e6;
// Start and end closer than this in XY (mm) make a full circle.
constexpr double kFullCircleSlack = 1e-9;

}  // namespace

MaterialMove material_move(const gcode::Motion& m, const config::Setup& setup) {
  const auto& o = setup.work_origin;
  auto work = [&](const geometry::Vec3& p) { return geometry::Vec3{p.x - o[0], p.y - o[1], p.z - o[2]}; };
  MaterialMove move;
  move.motion = m.kind == gcode::MotionKind::Rapid  ? Motion::Rapid
                : m.kind == gcode::MotionKind::Feed ? Motion::Linear
                : m.kind == gcode::MotionKind::ArcCw ? Motion::ArcCw
                                                     : Motion::ArcCcw;
  move.from = work(m.from_machine);
  move.to = work(m.to_machine);
  move.centre = work(m.centre_machine);
  move.process_on = m.deposition;
  move.line = m.line;
  return move;
}

std::vector<Segment> path_segments(const MaterialMove& move, double chord_tolerance) {
  if (!(chord_tolerance > 0)) throw std::invalid_argument("arc chord tolerance must be positive");
  if (move.motion == Motion::Rapid || move.motion == Motion::Linear) return {{move.from, move.to}};
  const double cx = move.centre.x, cy = move.centre.y;
  const double r0 = std::hypot(move.from.x - cx, move.from.y - cy);
  const double r1 = std::hypot(move.to.x - cx, move.to.y - cy);
  if (r0 == 0 || r1 == 0) return {{move.from, move.to}};  // degenerate: no circle to follow
  const double a0 = std::atan2(move.from.y - cy, move.from.x - cx);
  const double a1 = std::atan2(move.to.y - cy, move.to.x - cx);
  const double two_pi = 2 * std::numbers::pi;
  const bool full = std::hypot(move.to.x - move.from.x, move.to.y - move.from.y) < kFullCircleSlack;
  double sweep;
  if (move.motion == Motion::ArcCcw) {
    sweep = full ? two_pi : a1 - a0;
    while (sweep <= 0) sweep += two_pi;
  } else {
    sweep = full ? -two_pi : a1 - a0;
    while (sweep >= 0) sweep -= two_pi;
  }
  // A chord of angle phi on radius r is at most r (1 - cos(phi / 2)) from its arc.
  const double r = std::max(r0, r1);
  const double step = chord_tolerance >= r ? std::numbers::pi / 2
                                           : std::min(std::numbers::pi / 2, 2 * std::acos(1 - chord_tolerance / r));
  const int n = int(std::clamp(std::ceil(std::abs(sweep) / step), 1.0, kMaxChords));
  std::vector<Segment> out;
  out.reserve(std::size_t(n));
  Vec3 prev = move.from;
  for (int i = 1; i <= n; ++i) {
    Vec3 p;
    if (i == n) {
      p = move.to;
    } else {
      const double f = double(i) / n;
      const double a = a0 + sweep * f, rr = r0 + (r1 - r0) * f;
      p = {cx + rr * std::cos(a), cy + rr * std::sin(a), move.from.z + (move.to.z - move.from.z) * f};
    }
    out.push_back({prev, p});
    prev = p;
  }
  return out;
}

}  // namespace hybridctl::sim
