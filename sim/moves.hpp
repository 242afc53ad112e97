#pragma once
// The moves the material simulation replays: already interpreted G-code motion in the
// work frame (mm), with the source line for incidents.

#include <vector>

#include "config/machine.hpp"
#include "gcode/interpreter.hpp"
#include "sim/sweep.hpp"

namespace hybridctl::sim {

enum class Motion {
  Rapid,   // G0
  Linear,  // G1
  ArcCw,   // G2, XY plane
  ArcCcw,  // G3, XY plane
};

struct MaterialMove {
  Motion motion = Motion::Linear;
  Vec3 from, to;            // programmed point (tool tip, bead bottom) at start and end, mm
  Vec3 centre;              // arcs: the centre in XY (its z is ignored)
  bool process_on = false;  // deposition: the head deposits during the move (cutters ignore it)
  int line = 0;             // where the move comes from (G-code line), for incidents
};

// An interpreted motion as the material simulation replays it in the work frame of
// `setup` (machine coordinates less the setup's work origin): the one rule the simulated
// machine and exact verification (verification/) both follow.
MaterialMove material_move(const gcode::Motion& motion, const config::Setup& setup);

// The straight segments a move is simulated as: the move itself when it is straight. An
// arc becomes chords no farther than `chord_tolerance` mm from it (sagitta bound on its
// larger radius); the radius changes linearly from start to end, as does z (helix).
// An arc whose end equals its start in XY is a full turn. Throws std::invalid_argument
// for a non-positive tolerance.
std::vector<Segment> path_segments(const MaterialMove& move, double chord_tolerance);

}  // namespace hybridctl::sim
