#include "plan/deviation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/number_text.hpp"
#include "geometry/distance_field.hpp"

namespace hybridctl::plan {
namespace {

using geometry::FarthestVoxel;
using geometry::IndexBox;
using geometry::Solid;

// The air around a solid, near enough to hold the nearest air voxel of each of its
// voxels: the solid's box grown by one (a voxel outside it is never nearer).
Solid air_around(const Solid& s, const IndexBox& also) {
  const IndexBox b = box_union(s.bounding_box(), also);
  return complement(s, {{b.lo.x - 1, b.lo.y - 1, b.lo.z - 1}, {b.hi.x + 1, b.hi.y + 1, b.hi.z + 1}});
}

// The farther of two, with where it is.
void take_worst(const FarthestVoxel& f, const geometry::Lattice& lattice, double& worst,
                std::optional<geometry::Vec3>& at) {
  if (!f.voxel || (at && f.distance <= worst)) return;
  worst = f.distance;
  at = lattice.center(*f.voxel);
}

}  // namespace

double judged_limit(double tolerance, double voxel) {
  constexpr double kSlack = 1e-9;  // mm: a distance equal to the tolerance is within it
  return (tolerance >= voxel ? std::max(tolerance, std::sqrt(3.0) * voxel) : tolerance) + kSlack;
}

Deviation measure_deviation(const Solid& made, const Solid& design, const IndexBox& /*domain*/, double tolerance) {
  const Solid over = subtract(made, design), under = subtract(design, made);
  const geometry::Lattice& lattice = design.lattice();
  const double half = design.voxel_size() / 2;
  Deviation d;
  d.over_volume = over.volume();
  d.under_volume = under.volume();
  // From D's other side: material outside D from D, holes in D from D's air.
  const FarthestVoxel over_from_design = geometry::farthest_voxel(over, design);
  const FarthestVoxel under_from_air = geometry::farthest_voxel(under, air_around(design, under.bounding_box()));
  d.worst_over = over.empty() ? 0 : std::max(0.0, over_from_design.distance - half);
  d.worst_under = under.empty() ? 0 : std::max(0.0, under_from_air.distance - half);
  d.worst_distance = std::max(d.worst_over, d.worst_under);
  take_worst(over_from_design, lattice, d.worst_out, d.worst_out_at);
  take_worst(under_from_air, lattice, d.worst_out, d.worst_out_at);
  // From M's other side: missing design from the material made, filled air from M's air.
  take_worst(geometry::farthest_voxel(under, made), lattice, d.worst_missing, d.worst_missing_at);
  take_worst(geometry::farthest_voxel(over, air_around(made, over.bounding_box())), lattice, d.worst_missing,
             d.worst_missing_at);
  // Where one layer is within the tolerance (as it always is within the planning band), it
  // is whatever its direction: a wrong voxel that meets the other side only at an edge or
  // a corner (its centre sqrt(2) or sqrt(3) voxels away, round an edge or corner) is the same
  // one layer the grid resolves as a face neighbour, and what it means on the real
  // surface is exact verification's to judge.
  const double judged = judged_limit(tolerance, design.voxel_size());
  d.within_tolerance = d.worst_out <= judged && d.worst_missing <= judged;
  return d;
}

namespace {

std::string direction_text(const char* name, double worst, const std::optional<geometry::Vec3>& at, double tolerance) {
  if (std::isinf(worst)) return std::string(name) + " everything (nothing made)";
  std::string s = std::string(name) + " " + fixed_number(worst, 2) + " mm";
  if (at && worst > tolerance)
    s += " at (" + fixed_number(at->x, 2) + ", " + fixed_number(at->y, 2) + ", " + fixed_number(at->z, 2) + ")";
  return s;
}

}  // namespace

std::string deviation_text(const Deviation& d, double band) {
  // Where each is, only when it is beyond: one layer of voxels round an edge is within.
  const double beyond = d.within_tolerance ? std::numeric_limits<double>::infinity() : band;
  return fixed_number(d.over_volume, 1) + " mm\u00B3 over, " + fixed_number(d.under_volume, 1) + " mm\u00B3 under; " +
         direction_text("out", d.worst_out, d.worst_out_at, beyond) + ", " +
         direction_text("missing", d.worst_missing, d.worst_missing_at, beyond) + ": " +
         (d.within_tolerance ? "within" : "OUTSIDE") + " the planning band (" + shortest_number(band) + " mm)";
}

namespace {

std::string place_text(const char* what, const ExactPlace& p) {
  std::string out = std::string(what) + " " + (p.at_least ? "at least " : "") + fixed_number(p.mm, 3) + " mm";
  if (!p.at) return out;
  out += " at (" + fixed_number(p.at->x, 2) + ", " + fixed_number(p.at->y, 2) + ", " + fixed_number(p.at->z, 2) + ")";
  if (p.action > 0) out += " by action " + std::to_string(p.action) + (p.line > 0 ? " (line " + std::to_string(p.line) + ")" : "");
  else out += " (the start stock)";
  if (p.as_deposited) out += " as deposited";
  return out;
}

}  // namespace

std::string exact_deviation_text(const ExactDeviation& d) {
  return place_text("excess", d.excess) + ", " + place_text("gouge", d.gouge) + "; " +
         fixed_number(100 * d.within_share, 1) + " % of the surface within " + shortest_number(d.tolerance) + " mm: " +
         (d.within_tolerance() ? "within" : "OUTSIDE") + " tolerance";
}

}  // namespace hybridctl::plan
