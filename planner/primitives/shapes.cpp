#include "planner/primitives/shapes.hpp"

#include <algorithm>
#include <optional>
#include <variant>

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

// An instrument as a tool sweep (geometry/morphology.hpp): one axial cutting part that
// holds its tip (the definition's removal region keeps every free tip position, which the
// sweep does when the cutting part holds the origin) and an axial body along it. SM-max
// keeps the whole instrument clear of the design, SM-cons its body alone.
std::optional<geometry::ToolSweep> as_tool_sweep(const Instrument& in, bool maximal) {
  if (in.cutting.size() != 1) return std::nullopt;
  const auto* cutting = std::get_if<geometry::AxialBody>(&in.cutting.front());
  if (!cutting) return std::nullopt;
  bool holds_tip = false;
  for (const auto& section : cutting->sections) holds_tip = holds_tip || section.radius_squared_at(0.0) >= 0;
  if (!holds_tip) return std::nullopt;
  geometry::ToolSweep sweep{*cutting, {}};
  if (maximal) sweep.clearance.push_back(*cutting);
  for (const auto& e : in.body) {
    const auto* body = std::get_if<geometry::AxialBody>(&e);
    if (!body || !(body->direction == cutting->direction)) return std::nullopt;
    sweep.clearance.push_back(*body);
  }
  return sweep;
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

std::vector<Solid> removal_regions(const Solid& design, const std::vector<RemovalRequest>& requests, const IndexBox& domain,
                                   const std::function<void(std::size_t)>& done) {
  // Cutters are axial bodies: their removal regions are tool sweeps, computed together.
  // Anything else goes by the definition, one by one.
  std::vector<Solid> out(requests.size());
  std::vector<geometry::ToolSweep> sweeps;
  std::vector<std::size_t> swept;
  for (std::size_t i = 0; i < requests.size(); ++i) {
    if (auto sweep = as_tool_sweep(*requests[i].instrument, requests[i].maximal)) {
      sweeps.push_back(std::move(*sweep));
      swept.push_back(i);
    } else {
      const Instrument& in = *requests[i].instrument;
      out[i] = requests[i].maximal ? subtractive_maximal(design, in, domain) : subtractive_conservative(design, in, domain);
      if (done) done(i);
    }
  }
  std::vector<Solid> regions = geometry::tool_sweeps(design, sweeps, domain, [&](std::size_t k) {
    if (done) done(swept[k]);
  });
  for (std::size_t k = 0; k < swept.size(); ++k) out[swept[k]] = std::move(regions[k]);
  return out;
}

}  // namespace hybridctl::planner
