#pragma once
// Arc fitting (docs/toolpaths.md, "Arc fitting"): runs of straight feed moves that follow
// a circle, replaced by one G2/G3 move each, as a CAM post's arc fitter does.
//
//   Toolpath fitted = fit_arcs(std::move(path));        // defaults: 0.001 mm, arcs on
//   ArcFitStats stats;
//   auto moves = fit_arcs(path.start, path.moves, {.chord_tolerance = 0.01}, &stats);
//
// A run is a maximal sequence of consecutive `Feed` moves at the height of the point it
// starts from (planar: no helices), with one feed and one `process_on`, and no comment
// but on its first move (the comment goes on the arc). Rapids are never touched. Within a
// run, from its start, the longest prefix of at least `min_chords` moves that fits one
// arc becomes that arc, and the search goes on from its end; a prefix that fits none
// leaves its first move as it is.
//
// A prefix fits an arc when:
//  - the arc starts at the run's start point and ends exactly at the prefix's last point
//    (the centre is on the perpendicular bisector of the two, so both radii agree to
//    rounding; G-code's 4 decimals then keep them within 0.0003 mm, far inside LinuxCNC's
//    "radius to end of arc differs from radius to start" check);
//  - every point of every chord is within `chord_tolerance` of the circle (so every
//    original point and every chord's middle is, and every point of the arc is within it
//    of the polyline: the arc and the moves it replaces are within the tolerance of each
//    other both ways), and none lies outside it by more than `inward_tolerance`: the arc
//    stands out of the moves by up to the tolerance, away from its centre, as an arc does
//    from its own chords, and never cuts inside them. Why one-sided: a wall finishing
//    pass's chords are a polygon offset's, 0.0002..0.0012 mm off the design; its round
//    joins' vertices lie on their arcs with the design at the centre, and the offset of a
//    round hole's many sides has its sides' middles nearest the design, outside the circle
//    through its vertices. Either way an arc through the vertices keeps the pass's
//    standoff; an arc that passes inside the chords (a join fitted together with the
//    straight pieces leading into it) would take 0.001 mm of the standoff's 0.0002;
//  - the points turn one way round the centre, each chord by less than half a turn, in
//    all by at most `max_sweep_deg` (below 360: a full circle becomes two arcs);
//  - its radius is within [min_radius, max_radius]: flatter runs stay lines, and a tiny
//    radius would make the 0.0001 mm rounding of the program a sizeable fraction of it.
// The centre is that of the circle through the prefix's ends and its middle point (where
// a polygon offset's round join has its vertices: on the arc), or, when that circle does
// not fit, of the one refined along the bisector by least squares on the chords' points.

#include <cstddef>
#include <vector>

#include "toolpaths/toolpath.hpp"

namespace hybridctl::toolpaths {

// What plan export does with circular runs of feed moves.
enum class ArcOutput {
  Fit,    // replace them by G2/G3 arcs within the tolerance (the default)
  Lines,  // keep every move as the generator made it
};

struct ArcFitOptions {
  ArcOutput output = ArcOutput::Fit;  // fit_arcs ignores it: it is the caller's switch (plan export's)
  double chord_tolerance = 0.001;     // mm: how far the arc and the moves it replaces may be apart, both ways
  double inward_tolerance = 0.0001;   // mm: how far a point of the moves may lie outside the arc (<= chord_tolerance)
  int min_chords = 3;                 // an arc replaces at least this many moves (4 points)
  double min_radius = 0.5;            // mm: smaller circles stay lines
  double max_radius = 1000;           // mm: flatter runs stay lines
  double max_sweep_deg = 270;         // an arc turns at most this far (< 360: a full circle is two arcs)
};

// What a fit did, for messages and tests.
struct ArcFitStats {
  std::size_t arcs = 0;            // arcs made
  std::size_t moves_replaced = 0;  // feed moves they replaced
};

// `moves`, starting from `start`, with every run that fits an arc replaced by that arc.
// Throws std::invalid_argument for a tolerance, radius bound or chord count that cannot
// work (chord tolerance <= 0, inward tolerance outside [0, chord tolerance], min_chords < 2,
// max_sweep_deg outside (0, 360), radii not 0 < min <= max).
std::vector<PathMove> fit_arcs(const geometry::Vec3& start, const std::vector<PathMove>& moves,
                               const ArcFitOptions& options = {}, ArcFitStats* stats = nullptr);

// `path` with its moves fitted from `path.start` (where the post-processor's approach
// leaves the tool before the first move).
Toolpath fit_arcs(Toolpath path, const ArcFitOptions& options = {}, ArcFitStats* stats = nullptr);

}  // namespace hybridctl::toolpaths
