#include "instruments/elements.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "instruments/cutter.hpp"

namespace hybridctl::instruments {

using geometry::AxialBody;
using geometry::AxialSection;
using geometry::AxisDirection;

geometry::AxisDirection approach_direction(config::Approach a) {
  switch (a) {
    case config::Approach::PlusX: return {geometry::Axis::X, +1};
    case config::Approach::MinusX: return {geometry::Axis::X, -1};
    case config::Approach::PlusY: return {geometry::Axis::Y, +1};
    case config::Approach::MinusY: return {geometry::Axis::Y, -1};
    case config::Approach::PlusZ: return {geometry::Axis::Z, +1};
    case config::Approach::MinusZ: return {geometry::Axis::Z, -1};
  }
  return {};
}

AxialBody axial_body(std::vector<AxialSection> profile, config::Approach approach) {
  return AxialBody{approach_direction(approach), std::move(profile)};
}

geometry::StructuringElement bead_element(const Bead& bead, config::Approach approach) {
  const AxisDirection d = approach_direction(approach);
  const double w = bead.width / 2, h = bead.height / 2;
  if (bead.shape == config::BeadShape::Ellipsoid) {
    geometry::Vec3 radii{w, w, w};
    (d.axis == geometry::Axis::X ? radii.x : d.axis == geometry::Axis::Y ? radii.y : radii.z) = h;
    return geometry::Ellipsoid{radii};
  }
  return geometry::cylinder_body(d, w, bead.height);
}

AxialBody conservative_guard(const std::vector<AxialSection>& profile, double h) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  double finite_end = 0, tail_from = kInf, tail_radius = -1;
  for (const AxialSection& s : profile) {
    if (std::isinf(s.to)) {
      tail_from = std::min(tail_from, s.from);
      tail_radius = std::max(tail_radius, s.radius);
    } else {
      finite_end = std::max(finite_end, s.to);
    }
  }
  const double last = std::max(finite_end, std::isinf(tail_from) ? 0.0 : tail_from);
  const int levels = int(std::ceil(last / h)) + 2;
  AxialBody body{{geometry::Axis::Z, +1}, {}};
  for (int t = 0; t < levels; ++t) {
    const double lo = std::max(0.0, (t - 1) * h), hi = t * h;
    std::vector<double> samples;
    for (int i = 0; i <= kProfileSamplesPerVoxel; ++i) samples.push_back(lo + (hi - lo) * i / kProfileSamplesPerVoxel);
    for (const AxialSection& s : profile)
      for (double v : {s.from, s.to, s.centre})
        if (v >= lo && v <= hi) samples.push_back(v);
    double r2 = -1;
    for (double z : samples) r2 = std::max(r2, radius_squared_at(profile, z));
    if (r2 >= 0) body.sections.push_back({AxialSection::Kind::Cylinder, t * h - h / 4, t * h + h / 4, std::sqrt(r2), 0, 0});
  }
  if (tail_radius >= 0) body.sections.push_back({AxialSection::Kind::Cylinder, levels * h, kInf, tail_radius, 0, 0});
  return body;
}

}  // namespace hybridctl::instruments
