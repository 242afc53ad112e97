#include "planner/primitives/filled.hpp"

#include <algorithm>

#include "instruments/elements.hpp"
#include "planner/primitives/shapes.hpp"

namespace hybridctl::planner {

using geometry::Index3;
using geometry::IndexBox;
using geometry::Solid;

Solid column_filled(const Solid& region, geometry::AxisDirection build, const IndexBox& domain) {
  Solid out(region.lattice(), domain);
  const IndexBox bb = geometry::box_intersection(region.bounding_box(), domain);
  if (bb.empty()) return out;
  const int axis = build.axis == geometry::Axis::X ? 0 : build.axis == geometry::Axis::Y ? 1 : 2;
  const int ua = (axis + 1) % 3, va = (axis + 2) % 3;
  const int lo[3] = {bb.lo.x, bb.lo.y, bb.lo.z}, hi[3] = {bb.hi.x, bb.hi.y, bb.hi.z};
  for (int v = lo[va]; v < hi[va]; ++v)
    for (int u = lo[ua]; u < hi[ua]; ++u) {
      int c[3];
      c[ua] = u, c[va] = v;
      // The column's highest voxel towards the head: everything from the first layer up to it.
      int top = -1;
      for (int k = 0; k < hi[axis] - lo[axis] && top < 0; ++k) {
        c[axis] = build.sign > 0 ? hi[axis] - 1 - k : lo[axis] + k;
        if (region.contains({c[0], c[1], c[2]})) top = c[axis];
      }
      if (top < 0) continue;
      const int from = build.sign > 0 ? lo[axis] : top, to = build.sign > 0 ? top : hi[axis] - 1;
      for (int t = from; t <= to; ++t) {
        c[axis] = t;
        out.set({c[0], c[1], c[2]});
      }
    }
  return out;
}

std::size_t max_filled_primitive_count(const config::Machine& m) {
  std::size_t n = 0;
  for (const auto& head : m.heads)
    if (std::find(head.primitives.begin(), head.primitives.end(), config::PrimitiveKind::OAm) != head.primitives.end())
      n += m.setups.size();
  return n;
}

std::vector<Primitive> filled_primitives(const config::Machine& m, const Solid& design, const IndexBox& domain,
                                         const std::vector<Primitive>& primitives) {
  std::vector<Primitive> out;
  Solid removable(design.lattice(), domain);
  for (const Primitive& p : primitives)
    if (p.kind == PrimitiveKind::SmMax || p.kind == PrimitiveKind::SmCons) removable = unite(removable, p.region);
  const Solid whole_domain = Solid::filled(design.lattice(), domain);
  for (const Primitive& p : primitives) {
    if (p.kind != PrimitiveKind::OAm || p.setup.empty()) continue;
    const auto head = std::find_if(m.heads.begin(), m.heads.end(), [&](const auto& h) { return h.name == p.capability; });
    const auto setup = std::find_if(m.setups.begin(), m.setups.end(), [&](const auto& s) { return s.name == p.setup; });
    if (head == m.heads.end() || setup == m.setups.end()) continue;
    const Solid envelope = intersect(additive_conservative(design, bead_instrument(*head, setup->approach)), whole_domain);
    // The support cut took no design: the O-AM is whole as it is.
    if (subtract(intersect(envelope, design), p.region).empty()) continue;
    Solid filled = column_filled(envelope, instruments::approach_direction(setup->approach), domain);
    const Solid added = subtract(filled, design);
    const double kept = double(subtract(added, removable).voxel_count());
    if (added.voxel_count() == 0 || kept > (1 - kFilledRemovable) * double(added.voxel_count())) continue;
    if (filled == p.region) continue;
    Primitive f = p;
    f.label = p.label + ", filled";
    f.name.clear();
    f.region = std::move(filled);
    out.push_back(std::move(f));
  }
  return out;
}

}  // namespace hybridctl::planner
