#include "geometry/shapes.hpp"

#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

namespace hybridctl::geometry {
namespace {

using Interval = std::optional<std::pair<double, double>>;

void require_positive(double v, const char* what) {
  if (!(v > 0) || !std::isfinite(v)) throw std::invalid_argument(std::string(what) + " must be positive, got " + std::to_string(v));
}

// Fills, row by row, the voxels whose centre x lies in the row's interval [x0, x1).
template <typename RowInterval>
Solid fill_rows(const Lattice& lattice, const Box3& bounds, RowInterval interval) {
  const IndexBox domain = lattice.centers_within(bounds);
  Solid out(lattice, domain);
  const double h = lattice.voxel_size;
  for (int z = domain.lo.z; z < domain.hi.z; ++z)
    for (int y = domain.lo.y; y < domain.hi.y; ++y) {
      const Vec3 c = lattice.center({0, y, z});
      const Interval range = interval(c.y, c.z);
      if (!range) continue;
      const int i0 = std::max(domain.lo.x, int(std::ceil((range->first - lattice.origin.x) / h - 0.5)));
      const int i1 = std::min(domain.hi.x, int(std::ceil((range->second - lattice.origin.x) / h - 0.5)));
      out.set_run(y, z, i0, i1);
    }
  return out;
}

}  // namespace

Solid make_box(const Lattice& lattice, const Box3& box) {
  return fill_rows(lattice, box, [&](double y, double z) -> Interval {
    if (y < box.min.y || y >= box.max.y || z < box.min.z || z >= box.max.z) return std::nullopt;
    return std::pair{box.min.x, box.max.x};
  });
}

Solid make_ellipsoid(const Lattice& lattice, Vec3 c, Vec3 r) {
  require_positive(r.x, "ellipsoid radius X");
  require_positive(r.y, "ellipsoid radius Y");
  require_positive(r.z, "ellipsoid radius Z");
  const Box3 bounds{{c.x - r.x, c.y - r.y, c.z - r.z}, {c.x + r.x, c.y + r.y, c.z + r.z}};
  return fill_rows(lattice, bounds, [&](double y, double z) -> Interval {
    const double dy = (y - c.y) / r.y, dz = (z - c.z) / r.z;
    const double rest = 1.0 - dy * dy - dz * dz;
    if (rest < 0) return std::nullopt;
    const double half = r.x * std::sqrt(rest);
    return std::pair{c.x - half, std::nextafter(c.x + half, INFINITY)};  // closed at both ends
  });
}

Solid make_sphere(const Lattice& lattice, Vec3 centre, double radius) {
  return make_ellipsoid(lattice, centre, {radius, radius, radius});
}

Solid make_cylinder(const Lattice& lattice, Axis axis, Vec3 b, double radius, double length) {
  require_positive(radius, "cylinder radius");
  require_positive(length, "cylinder length");
  const double r = radius;
  switch (axis) {
    case Axis::X: {
      const Box3 bounds{{b.x, b.y - r, b.z - r}, {b.x + length, b.y + r, b.z + r}};
      return fill_rows(lattice, bounds, [&](double y, double z) -> Interval {
        if ((y - b.y) * (y - b.y) + (z - b.z) * (z - b.z) > r * r) return std::nullopt;
        return std::pair{b.x, b.x + length};
      });
    }
    case Axis::Y: {
      const Box3 bounds{{b.x - r, b.y, b.z - r}, {b.x + r, b.y + length, b.z + r}};
      return fill_rows(lattice, bounds, [&](double y, double z) -> Interval {
        const double rest = r * r - (z - b.z) * (z - b.z);
        if (rest < 0 || y < b.y || y >= b.y + length) return std::nullopt;
        const double half = std::sqrt(rest);
        return std::pair{b.x - half, std::nextafter(b.x + half, INFINITY)};
      });
    }
    case Axis::Z: {
      const Box3 bounds{{b.x - r, b.y - r, b.z}, {b.x + r, b.y + r, b.z + length}};
      return fill_rows(lattice, bounds, [&](double y, double z) -> Interval {
        const double rest = r * r - (y - b.y) * (y - b.y);
        if (rest < 0 || z < b.z || z >= b.z + length) return std::nullopt;
        const double half = std::sqrt(rest);
        return std::pair{b.x - half, std::nextafter(b.x + half, INFINITY)};
      });
    }
  }
  throw std::invalid_argument("unknown cylinder axis");
}

}  // namespace hybridctl::geometry
