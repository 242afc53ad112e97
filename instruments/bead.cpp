#include "instruments/bead.hpp"

#include <algorithm>
#include <cmath>

namespace hybridctl::instruments {

Bead bead_of(const config::AdditiveHead& head) {
  Bead bead{head.bead.shape, head.bead.width, head.bead.height, {}, head.support};
  if (head.nozzle) {
    const config::Nozzle& n = *head.nozzle;
    bead.body.push_back({geometry::AxialSection::Kind::Cylinder, n.standoff, n.standoff + n.length, n.diameter / 2, 0, 0});
  }
  return bead;
}

double bead_half_width_at(const Bead& bead, double dz) {
  if (!(dz >= 0) || dz > bead.height) return 0;
  const double r = bead.width / 2, half = bead.height / 2;
  if (bead.shape != config::BeadShape::Ellipsoid || dz <= half) return r;
  const double u = (dz - half) / half;
  return r * std::sqrt(std::max(0.0, 1 - u * u));
}

double bead_wall_scallop(const Bead& bead, double layer_height) {
  const double widest = bead_half_width_at(bead, 0);
  // Narrowest just under the next layer's bottom (narrowing all the way up).
  if (!(layer_height > 0) || layer_height > bead.height) return widest;
  return widest - bead_half_width_at(bead, layer_height);
}

double bead_top_dip(const Bead& bead, double spacing) {
  if (bead.shape != config::BeadShape::Ellipsoid || !(bead.width > 0)) return 0;
  const double u = std::min(1.0, spacing / bead.width);
  return bead.height / 2 * (1 - std::sqrt(1 - u * u));
}

int head_tool_number(const config::AdditiveHead& head, int fallback) {
  return head.tool_number > 0 ? head.tool_number : fallback;
}

int head_tool_number(const config::Machine& machine, std::size_t head_index) {
  return head_tool_number(machine.heads.at(head_index), config::kDefaultHeadToolNumberBase + int(head_index));
}

}  // namespace hybridctl::instruments
