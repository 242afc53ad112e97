#include "planner/primitive_shapes.hpp"

#include <algorithm>

namespace hybridctl::planner {
namespace {

using geometry::IndexBox;
using geometry::Solid;
using geometry::StructuringElement;

std::vector<StructuringElement> reflected_all(const std::vector<StructuringElement>& elements) {
  std::vector<StructuringElement> out;
  for (const auto& e : elements) out.push_back(geometry::reflected(e));
  return out;
}

std::vector<StructuringElement> joined(std::vector<StructuringElement> a, const std::vector<StructuringElement>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

// Dilation and erosion by a union of elements: the union of the dilations, the
// intersection of the erosions.
Solid dilate_union(const Solid& s, const std::vector<StructuringElement>& elements, const IndexBox& domain) {
  Solid out(s.lattice(), domain);
  for (const auto& e : elements) out = unite(out, geometry::dilate(s, e, domain));
  return domain.empty() ? out : intersect(out, Solid::filled(s.lattice(), domain));
}

Solid erode_union(const Solid& s, const std::vector<StructuringElement>& elements) {
  if (elements.empty()) return s;
  Solid out = geometry::erode(s, elements.front());
  for (std::size_t i = 1; i < elements.size(); ++i) out = intersect(out, geometry::erode(s, elements[i]));
  return out;
}

// The largest finite reach of the elements, to pad the working domain so erosion near
// its border does not invent accessible regions.
IndexBox padded(const IndexBox& domain, const std::vector<StructuringElement>& elements, double h) {
  int reach = 1;
  for (const auto& e : elements) {
    const IndexBox ext = geometry::element_extent(e, h);
    for (int v : {-ext.lo.x, -ext.lo.y, -ext.lo.z, ext.hi.x, ext.hi.y, ext.hi.z})
      if (v < geometry::kUnboundedExtent) reach = std::max(reach, v + 1);
  }
  return {{domain.lo.x - reach, domain.lo.y - reach, domain.lo.z - reach},
          {domain.hi.x + reach, domain.hi.y + reach, domain.hi.z + reach}};
}

Solid removal_region(const Solid& design, const std::vector<StructuringElement>& grow_by,
                     const std::vector<StructuringElement>& cutting, const IndexBox& domain) {
  const IndexBox work = padded(domain, cutting, design.voxel_size());
  const Solid obstacle = grow_by.empty() ? design : dilate_union(design, reflected_all(grow_by), work);
  const Solid kept = erode_union(obstacle, reflected_all(cutting));
  return subtract(Solid::filled(design.lattice(), domain), kept);
}

}  // namespace

Solid additive_maximal(const Solid& design, const Instrument& instrument) {
  const Solid positions = erode_union(design, joined(instrument.cutting, instrument.body));
  return dilate_union(positions, instrument.cutting, {});
}

Solid additive_conservative(const Solid& design, const Instrument& instrument) {
  const Solid positions = instrument.body.empty() ? design : erode_union(design, instrument.body);
  return dilate_union(positions, instrument.cutting, {});
}

Solid subtractive_maximal(const Solid& design, const Instrument& instrument, const IndexBox& domain) {
  return removal_region(design, joined(instrument.cutting, instrument.body), instrument.cutting, domain);
}

Solid subtractive_conservative(const Solid& design, const Instrument& instrument, const IndexBox& domain) {
  return removal_region(design, instrument.body, instrument.cutting, domain);
}

}  // namespace hybridctl::planner
