#include "planner/primitives/repair.hpp"

#include <cmath>
#include <cstdio>

#include "geometry/morphology.hpp"
#include "instruments/elements.hpp"
#include "instruments/support_rule.hpp"
#include "planner/primitives/support.hpp"

namespace hybridctl::planner {

std::vector<Primitive> repair_primitives(const config::Machine& machine, const geometry::Solid& design,
                                         const geometry::Solid& stock, double tolerance, const geometry::IndexBox& domain,
                                         const std::vector<Primitive>& primitives) {
  std::vector<Primitive> out;
  const geometry::Solid missing = subtract(design, stock);
  if (missing.empty()) return out;
  char what[96];
  std::snprintf(what, sizeof what, ", near the missing %.0f mm\u00B3", missing.volume());
  for (const Primitive& p : primitives) {
    if (p.kind != PrimitiveKind::UAm && p.kind != PrimitiveKind::OAm) continue;
    if (p.label.find(", from z") != std::string::npos || p.label.find(", near") != std::string::npos) continue;
    const config::AdditiveHead* head = machine.find_head(p.capability);
    const config::Setup* setup = machine.find_setup(p.setup);
    if (!head || !setup) continue;
    // Within a bead and the tolerance of what is missing: the overfill that covers it.
    const double reach = head->bead.width + tolerance;
    const geometry::Solid near = dilate(missing, geometry::Ball{reach}, domain);
    geometry::Solid region = self_supporting(intersect(p.region, near), instruments::approach_direction(setup->approach),
                                             instruments::support_rule(head->support, design.voxel_size()), &stock);
    // Only what adds to the stock, and only when it differs from the whole-part deposit.
    if (intersect(region, missing).empty() || region.volume() >= p.region.volume()) continue;
    Primitive local = p;
    local.label = p.label + what;
    local.region = std::move(region);
    out.push_back(std::move(local));
  }
  return out;
}

}  // namespace hybridctl::planner
