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

std::vector<Solid> removal_regions(const Solid& design, const std::vector<RemovalRequest>& requests, const IndexBox& domain,
                                   const std::function<void(std::size_t)>& done) {
  const double h = design.voxel_size();
  // One working box for all: padded by the farthest-reaching cutter.
  std::vector<StructuringElement> all_cutting;
  for (const auto& r : requests) all_cutting.insert(all_cutting.end(), r.instrument->cutting.begin(), r.instrument->cutting.end());
  const IndexBox work = padded(domain, all_cutting, h);

  // Every instrument's reflected cutter and body elements, once each, grown together.
  std::vector<const Instrument*> instruments;
  for (const auto& r : requests)
    if (std::find(instruments.begin(), instruments.end(), r.instrument) == instruments.end()) instruments.push_back(r.instrument);
  std::vector<StructuringElement> elements;
  struct Span {
    std::size_t cutting_begin, body_begin, end;
  };
  std::vector<Span> spans;
  for (const Instrument* in : instruments) {
    Span sp{elements.size(), 0, 0};
    for (const auto& e : in->cutting) elements.push_back(geometry::reflected(e));
    sp.body_begin = elements.size();
    for (const auto& e : in->body) elements.push_back(geometry::reflected(e));
    sp.end = elements.size();
    spans.push_back(sp);
  }
  const std::vector<Solid> grown = geometry::dilate_each(design, elements, work);

  std::vector<Solid> out;
  out.reserve(requests.size());
  for (std::size_t i = 0; i < requests.size(); ++i) {
    const RemovalRequest& r = requests[i];
    const Span& sp = spans[std::size_t(std::find(instruments.begin(), instruments.end(), r.instrument) - instruments.begin())];
    const std::size_t first = r.maximal ? sp.cutting_begin : sp.body_begin;
    Solid obstacle = design;
    if (first < sp.end) {
      obstacle = Solid(design.lattice(), work);
      for (std::size_t e = first; e < sp.end; ++e) obstacle = unite(obstacle, grown[e]);
      obstacle = intersect(obstacle, Solid::filled(design.lattice(), work));
    }
    const Solid kept = erode_union(obstacle, reflected_all(r.instrument->cutting));
    out.push_back(subtract(Solid::filled(design.lattice(), domain), kept));
    if (done) done(i);
  }
  return out;
}

}  // namespace hybridctl::planner
