#include "planner/pipeline/unreached_corners.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "common/number_text.hpp"
#include "instruments/bead.hpp"

namespace hybridctl::planner {
namespace {

std::string mm(double v) { return trimmed_number(v, 2); }

// Whether every voxel centre within `radius` of `at` is in `stock`, or none is.
bool away_from_faces(const geometry::Solid& stock, const geometry::Vec3& at, double radius) {
  const geometry::IndexBox box = stock.lattice().centers_within(
      {{at.x - radius, at.y - radius, at.z - radius}, {at.x + radius, at.y + radius, at.z + radius}});
  int in = 0, out = 0;
  for (int z = box.lo.z; z < box.hi.z; ++z)
    for (int y = box.lo.y; y < box.hi.y; ++y)
      for (int x = box.lo.x; x < box.hi.x; ++x) (stock.contains({x, y, z}) ? in : out) += 1;
  return in == 0 || out == 0;
}

}  // namespace

WallsAsDeposited walls_as_deposited(const config::Machine& machine, double tolerance) {
  WallsAsDeposited w;
  double layers = 0;
  for (const config::AdditiveHead& head : machine.heads) {
    const double scallop = instruments::bead_wall_scallop(instruments::bead_of(head), head.layer_height);
    const double best = head.accuracy + scallop / 2;
    if (best <= tolerance) w.within = true;
    // A head whose accuracy alone is past the tolerance is past it at every height.
    if (head.accuracy <= tolerance) layers = std::max(layers, head.layer_height);
    w.said += (w.said.empty() ? "" : "; ") + head.name + " within " + mm(best) + " mm (its accuracy " +
              mm(head.accuracy) + " mm" + (scallop > 0 ? " and half its layers' " + mm(scallop) + " mm scallop" : "") +
              ")";
  }
  w.min_stretch = 2 * layers;
  return w;
}

std::vector<plan::UnreachedCorner> corners_no_instrument_makes(const PlanningResult& r, const WallsAsDeposited& walls,
                                                               const plan::CornerFinder& find) {
  if (walls.within || !find) return {};
  std::vector<plan::UnreachedCorner> out;
  const double radius = r.tolerance + 2 * r.lattice.voxel_size;
  for (plan::UnreachedCorner& c : find(r.design_mesh, r.tolerance, walls.min_stretch)) {
    bool away = true;
    const int steps = std::max(1, int(std::ceil((c.to.z - c.from.z) / r.lattice.voxel_size)));
    for (int k = 0; k <= steps && away; ++k) {
      const geometry::Vec3 at{c.from.x, c.from.y, c.from.z + (c.to.z - c.from.z) * k / steps};
      for (const Primitive& p : r.primitives)
        if (p.kind == PrimitiveKind::RawStock && !away_from_faces(p.region, at, radius)) away = false;
    }
    if (away) out.push_back(std::move(c));
  }
  return out;
}

std::string corner_in_words(const plan::UnreachedCorner& c, double tolerance) {
  char at[96];
  std::snprintf(at, sizeof at, "(%.2f, %.2f) mm, z %.1f to %.1f", c.from.x, c.from.y, c.from.z, c.to.z);
  return "the inside corner at " + std::string(at) + " (" + trimmed_number(c.air_angle, 1) +
         " degrees of air): no cutter comes within " + mm(tolerance) + " mm of it (" + c.nearest_by + " stays " +
         mm(c.nearest) + " mm off)";
}

Verdict corner_refusal(const std::vector<plan::UnreachedCorner>& corners, const WallsAsDeposited& walls,
                       double tolerance) {
  Verdict v;
  v.outcome = Verdict::Outcome::NotManufacturable;
  v.decided_without_search = true;
  const std::size_t n = corners.size();
  v.summary = "no instrument of the machine makes " +
              (n == 1 ? std::string("an inside corner") : std::to_string(n) + " inside corners") + " within the " +
              mm(tolerance) + " mm tolerance; the first is " + corner_in_words(corners.front(), tolerance) +
              "; and no head lays a wall within it as deposited (" + walls.said + ")";
  return v;
}

}  // namespace hybridctl::planner
