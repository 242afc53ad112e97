// Structuring elements (offsets, extents), where a dilation works, and the choice among
// the algorithms (morphology_internal.hpp lists their files); erosion, opening and closing
// built on dilation; the farthest distance between two solids.

#include "geometry/morphology.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "geometry/morphology_internal.hpp"

namespace hybridctl::geometry {

using namespace detail;

double AxialSection::radius_squared_at(double z) const {
  if (z < from - kLengthSlack * std::max(1.0, std::abs(from)) || z > to + kLengthSlack * std::max(1.0, std::abs(to)))
    return -1;
  switch (kind) {
    case Kind::Cylinder: return radius * radius;
    case Kind::Sphere: return radius * radius - (z - centre) * (z - centre);
    case Kind::Torus: {
      const double tube_sq = radius * radius - (z - centre) * (z - centre);
      if (tube_sq < 0) return -1;
      const double r = ring + std::sqrt(tube_sq);
      return r * r;
    }
  }
  return -1;
}

AxialBody cylinder_body(AxisDirection direction, double radius, double length) {
  return {direction, {{AxialSection::Kind::Cylinder, 0, length, radius, 0, 0}}};
}

AxialBody ray_body(AxisDirection direction) {
  return {direction, {{AxialSection::Kind::Cylinder, 0, kInf, 0, 0, 0}}};
}

StructuringElement reflected(const StructuringElement& element) {
  if (const auto* body = std::get_if<AxialBody>(&element)) {
    AxialBody r = *body;
    r.direction = r.direction.reversed();
    return r;
  }
  if (const auto* set = std::get_if<VoxelOffsets>(&element)) {
    VoxelOffsets r = *set;
    for (Index3& d : r.offsets) d = {-d.x, -d.y, -d.z};
    return r;
  }
  return element;  // balls and ellipsoids are symmetric
}

std::vector<Index3> offsets_of(const StructuringElement& element, double h, int max_length_voxels) {
  std::vector<Index3> out;
  if (const auto* ball = std::get_if<Ball>(&element)) {
    const double r = ball->radius / h, r2 = r * r;
    const int n = int(std::floor(r));
    for (int z = -n; z <= n; ++z)
      for (int y = -n; y <= n; ++y)
        for (int x = -n; x <= n; ++x)
          if (double(x * x) + double(y * y) + double(z * z) <= r2) out.push_back({x, y, z});
  } else if (const auto* e = std::get_if<Ellipsoid>(&element)) {
    const double wx = (h / e->radii.x) * (h / e->radii.x), wy = (h / e->radii.y) * (h / e->radii.y),
                 wz = (h / e->radii.z) * (h / e->radii.z);
    const int nx = int(std::floor(e->radii.x / h)), ny = int(std::floor(e->radii.y / h)), nz = int(std::floor(e->radii.z / h));
    for (int z = -nz; z <= nz; ++z)
      for (int y = -ny; y <= ny; ++y)
        for (int x = -nx; x <= nx; ++x)
          if (wx * double(x * x) + wy * double(y * y) + wz * double(z * z) <= 1.0) out.push_back({x, y, z});
  } else if (const auto* body = std::get_if<AxialBody>(&element)) {
    const AxialLevels levels = axial_levels(*body, h);
    const Axis a = body->direction.axis;
    const int last = levels.tail_from >= 0 ? std::max(int(levels.radius_sq.size()), max_length_voxels)
                                           : int(levels.radius_sq.size());
    for (int t = 0; t < last; ++t) {
      const double r2 = t < int(levels.radius_sq.size()) ? levels.radius_sq[std::size_t(t)] : levels.tail_radius_sq;
      if (r2 < 0) continue;
      const int n = int(std::floor(std::sqrt(r2)));
      for (int v = -n; v <= n; ++v)
        for (int u = -n; u <= n; ++u) {
          if (double(u * u) + double(v * v) > r2) continue;
          Index3 d;
          component(d, a) = body->direction.sign * t;
          component(d, a == Axis::X ? Axis::Y : Axis::X) = u;
          component(d, a == Axis::Z ? Axis::Y : Axis::Z) = v;
          out.push_back(d);
        }
    }
  } else {
    out = std::get<VoxelOffsets>(element).offsets;
  }
  return out;
}

IndexBox element_extent(const StructuringElement& element, double h) {
  if (const auto* body = std::get_if<AxialBody>(&element)) {
    const AxialLevels levels = axial_levels(*body, h);
    double r2 = levels.tail_radius_sq;
    for (double v : levels.radius_sq) r2 = std::max(r2, v);
    const int n = r2 >= 0 ? int(std::floor(std::sqrt(r2))) : 0;
    IndexBox box{{-n, -n, -n}, {n + 1, n + 1, n + 1}};
    const Axis a = body->direction.axis;
    const int length = levels.tail_from >= 0 ? kUnboundedExtent : std::max(int(levels.radius_sq.size()), 1);
    if (body->direction.sign > 0) {
      component(box.lo, a) = 0;
      component(box.hi, a) = length;
    } else {
      component(box.lo, a) = levels.tail_from >= 0 ? -kUnboundedExtent : -length + 1;
      component(box.hi, a) = 1;
    }
    return box;
  }
  const std::vector<Index3> offsets = offsets_of(element, h);
  if (offsets.empty()) return {};
  IndexBox box{{INT32_MAX, INT32_MAX, INT32_MAX}, {INT32_MIN, INT32_MIN, INT32_MIN}};
  for (const Index3& d : offsets) {
    box.lo = {std::min(box.lo.x, d.x), std::min(box.lo.y, d.y), std::min(box.lo.z, d.z)};
    box.hi = {std::max(box.hi.x, d.x + 1), std::max(box.hi.y, d.y + 1), std::max(box.hi.z, d.z + 1)};
  }
  return box;
}

namespace {

// Where a dilation works: the result's domain, and the solid's voxels that can reach it
// (the domain minus the element's extent). Empty source: the result is empty.
struct Placement {
  IndexBox ext, domain, source;
};

Placement place(const Solid& solid, const StructuringElement& element, const IndexBox& requested_domain) {
  Placement p;
  p.ext = element_extent(element, solid.voxel_size());
  const IndexBox bbox = solid.bounding_box();
  if (requested_domain.empty() && !is_finite_extent(p.ext)) {
    throw std::invalid_argument("dilation by an infinite element needs a domain to clip to");
  }
  p.domain = requested_domain.empty() ? grow(bbox, p.ext) : requested_domain;
  if (bbox.empty() || p.ext.empty() || p.domain.empty()) return p;
  const IndexBox& ext = p.ext;
  const IndexBox reflected_ext{{-(ext.hi.x - 1), -(ext.hi.y - 1), -(ext.hi.z - 1)}, {-ext.lo.x + 1, -ext.lo.y + 1, -ext.lo.z + 1}};
  p.source = box_intersection(bbox, grow(p.domain, reflected_ext));
  return p;
}

}  // namespace

std::vector<Solid> dilate_each(const Solid& solid, const std::vector<StructuringElement>& elements, const IndexBox& domain) {
  std::vector<Solid> out(elements.size());
  // Axial bodies along one axis: one distance transform across it, over the union of
  // their working boxes, up to the widest radius among them.
  for (Axis axis : {Axis::X, Axis::Y, Axis::Z}) {
    std::vector<std::size_t> group;
    IndexBox work;
    double widest = -1;
    for (std::size_t i = 0; i < elements.size(); ++i) {
      const auto* body = std::get_if<AxialBody>(&elements[i]);
      if (!body || body->direction.axis != axis) continue;
      const Placement p = place(solid, elements[i], domain);
      if (p.source.empty()) {
        out[i] = Solid(solid.lattice(), p.domain);
        continue;
      }
      const IndexBox w = box_union(p.source, p.domain);
      work = work.empty() ? w : box_union(work, w);
      widest = std::max(widest, widest_radius_sq(axial_levels(*body, solid.voxel_size())));
      group.push_back(i);
    }
    if (group.empty()) continue;
    const DenseGrid<float> perp = distance_across(solid, axis, work, widest);
    for (std::size_t i : group)
      out[i] = sweep_axial(perp, std::get<AxialBody>(elements[i]), solid.lattice(), place(solid, elements[i], domain).domain);
  }
  for (std::size_t i = 0; i < elements.size(); ++i)
    if (!std::holds_alternative<AxialBody>(elements[i])) out[i] = dilate(solid, elements[i], domain);
  return out;
}

Solid dilate(const Solid& solid, const StructuringElement& element, const IndexBox& requested_domain,
             MorphologyMethod method) {
  const double h = solid.voxel_size();
  const Placement placement = place(solid, element, requested_domain);
  const IndexBox& ext = placement.ext;
  const IndexBox& domain = placement.domain;
  const IndexBox& source = placement.source;
  if (source.empty()) return Solid(solid.lattice(), domain);

  if (method == MorphologyMethod::BruteForce || method == MorphologyMethod::Fft) {
    // Infinite bodies are cut where they leave the domain.
    const int reach = std::max({domain.hi.x - source.lo.x, source.hi.x - domain.lo.x, domain.hi.y - source.lo.y,
                                source.hi.y - domain.lo.y, domain.hi.z - source.lo.z, source.hi.z - domain.lo.z});
    const std::vector<Index3> offsets = offsets_of(element, h, reach + 1);
    if (method == MorphologyMethod::BruteForce) return dilate_brute_force(solid, offsets, domain);
    return dilate_fft(solid, offsets, source, domain);
  }
  const bool finite_element = is_finite_extent(ext);
  if (method == MorphologyMethod::Shifts) {
    if (!finite_element) throw std::invalid_argument("the shift method needs a finite element");
    return dilate_shifts(solid, offsets_of(element, h), source, domain);
  }
  if (method == MorphologyMethod::Auto && finite_element && !std::holds_alternative<AxialBody>(element)) {
    const IndexBox size = ext;
    const double box_voxels = double(size.hi.x - size.lo.x) * double(size.hi.y - size.lo.y) * double(size.hi.z - size.lo.z);
    if (box_voxels <= 4.0 * double(kShiftOffsetLimit)) {
      std::vector<Index3> offsets = offsets_of(element, h);
      if (offsets.size() <= kShiftOffsetLimit) return dilate_shifts(solid, offsets, source, domain);
    }
  }
  // The working box holds the sources and the domain.
  const IndexBox work = box_union(source, domain);
  if (const auto* ball = std::get_if<Ball>(&element)) {
    DenseGrid<float> g = distance_seed<float>(solid, work);
    const double r = ball->radius / h;
    distance_pass(g, Axis::X, 1.0, r * r, true);
    distance_pass(g, Axis::Y, 1.0, r * r, false);
    distance_pass(g, Axis::Z, 1.0, r * r, false);
    return threshold_into(g, r * r, solid.lattice(), domain);
  }
  if (const auto* e = std::get_if<Ellipsoid>(&element)) {
    DenseGrid<double> g = distance_seed<double>(solid, work);
    distance_pass(g, Axis::X, (h / e->radii.x) * (h / e->radii.x), 1.0, true);
    distance_pass(g, Axis::Y, (h / e->radii.y) * (h / e->radii.y), 1.0, false);
    distance_pass(g, Axis::Z, (h / e->radii.z) * (h / e->radii.z), 1.0, false);
    return threshold_into(g, 1.0, solid.lattice(), domain);
  }
  if (const auto* body = std::get_if<AxialBody>(&element)) return dilate_axial(solid, *body, work, domain);
  if (method == MorphologyMethod::DistanceTransform)
    throw std::invalid_argument("distance transforms serve balls, ellipsoids and axial bodies only");
  return dilate_fft(solid, offsets_of(element, h), source, domain);
}

Solid erode(const Solid& solid, const StructuringElement& element, MorphologyMethod method) {
  const IndexBox bbox = solid.bounding_box();
  if (bbox.empty()) return Solid(solid.lattice(), {});
  // Outside the solid's box everything is air; one layer of it beyond the element's
  // reach (or beyond the box, for infinite elements) is enough for the complement.
  const IndexBox ext = element_extent(element, solid.voxel_size());
  const Index3 size{bbox.hi.x - bbox.lo.x, bbox.hi.y - bbox.lo.y, bbox.hi.z - bbox.lo.z};
  auto low = [](int e, int n) { return e <= -kUnboundedExtent ? -n - 1 : e; };
  auto high = [](int e, int n) { return e >= kUnboundedExtent ? n + 2 : e; };
  const IndexBox margin{{low(ext.lo.x, size.x), low(ext.lo.y, size.y), low(ext.lo.z, size.z)},
                        {high(ext.hi.x, size.x), high(ext.hi.y, size.y), high(ext.hi.z, size.z)}};
  const IndexBox world = grow(bbox, margin);
  const Solid air = complement(solid, world);
  // p survives when p + B misses the air: p is not in air (+) (-B).
  const Solid reached = dilate(air, reflected(element), bbox, method);
  return subtract(Solid::filled(solid.lattice(), bbox), reached);
}

Solid open(const Solid& solid, const StructuringElement& element, MorphologyMethod method) {
  return dilate(erode(solid, element, method), element, {}, method);
}

Solid close(const Solid& solid, const StructuringElement& element, MorphologyMethod method) {
  return erode(dilate(solid, element, {}, method), element, method);
}

}  // namespace hybridctl::geometry

namespace hybridctl::geometry {

namespace {

// The largest squared distance (voxels^2) from `from` to `to` computed inside `work`:
// exact whenever it is at most `exact_up_to` (a nearer voxel of `to` outside `work`
// would be farther than that from every voxel of `from` in it).
double farthest_squared_within(const Solid& from, const Solid& to, const IndexBox& work) {
  DenseGrid<float> g = distance_seed<float>(to, work);
  distance_pass(g, Axis::X, 1.0, kInf, true);
  distance_pass(g, Axis::Y, 1.0, kInf, false);
  distance_pass(g, Axis::Z, 1.0, kInf, false);
  double worst = 0;
  from.for_each_voxel([&](Index3 v) {
    worst = std::max(worst, double(g.values[g.index(v.x - work.lo.x, v.y - work.lo.y, v.z - work.lo.z)]));
  });
  return worst;
}

}  // namespace

double farthest_distance(const Solid& from, const Solid& to) {
  const IndexBox fb = from.bounding_box();
  if (fb.empty()) return 0;
  const IndexBox tb = to.bounding_box();
  if (tb.empty()) return std::numeric_limits<double>::infinity();
  // Deviations are usually a few voxels deep: look near `from` first, and over the
  // whole extent only when something there is farther than the margin.
  constexpr int kNear = 16;
  const IndexBox near = box_intersection(box_union(fb, tb), grow(fb, {{-kNear, -kNear, -kNear}, {kNear + 1, kNear + 1, kNear + 1}}));
  double worst = farthest_squared_within(from, to, near);
  if (worst > double(kNear) * double(kNear)) worst = farthest_squared_within(from, to, box_union(fb, tb));
  return std::sqrt(worst) * from.voxel_size();
}

}  // namespace hybridctl::geometry
