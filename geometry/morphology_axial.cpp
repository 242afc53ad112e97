// Dilation by axial bodies (cutters with shank and holder, cylindrical beads, rays): the
// body is a radius per level along its axis; the solid's distances across the axis are
// computed once and each run of levels of equal radius is swept along the axis.

#include <cmath>
#include <map>
#include <stdexcept>

#include "geometry/morphology_internal.hpp"

namespace hybridctl::geometry::detail {

AxialLevels axial_levels(const AxialBody& body, double h) {
  AxialLevels levels;
  double finite_end = 0;
  for (const AxialSection& s : body.sections) {
    if (std::isinf(s.to)) {
      if (s.kind != AxialSection::Kind::Cylinder) throw std::invalid_argument("only a cylinder section may be infinite");
      const int from = int(std::ceil(s.from / h - kLengthSlack));
      if (levels.tail_from < 0 || from < levels.tail_from) levels.tail_from = from;
      levels.tail_radius_sq = std::max(levels.tail_radius_sq, (s.radius / h) * (s.radius / h));
    } else {
      finite_end = std::max(finite_end, s.to);
    }
  }
  int count = int(std::floor(finite_end / h + kLengthSlack)) + 1;
  if (levels.tail_from >= 0) count = std::max(count, levels.tail_from);
  levels.radius_sq.assign(std::size_t(std::max(count, 0)), -1.0);
  for (int t = 0; t < count; ++t) {
    const double z = t * h;
    double best = -1;
    for (const AxialSection& s : body.sections) {
      const double r2 = s.radius_squared_at(z);
      if (r2 >= 0) best = std::max(best, r2 / (h * h));
    }
    if (levels.tail_from >= 0 && t >= levels.tail_from) best = std::max(best, levels.tail_radius_sq);
    levels.radius_sq[std::size_t(t)] = best;
  }
  // Finite sections overlapping the tail widen it only where they are; levels past
  // `count` are the tail alone.
  return levels;
}

namespace {

// Dilation along one axis by offsets {sign * t : t in [lo, hi]} (hi may be unbounded),
// OR-ed into `out`: out[p] |= exists s with mask[s] and p - s = sign * t.
// Sources are the voxels where perp <= r2 (the level's radius reaches the solid), read
// straight from the distances: no mask pass per radius.
void axial_dilate(const DenseGrid<float>& mask, double r2, DenseGrid<std::uint8_t>& out, Axis axis, int sign, int lo,
                  std::int64_t hi) {
  const int n = mask.size(axis);
  const std::size_t stride = mask.stride(axis);
  // Walk each line in the direction of the offsets, so sources come before their
  // images, remembering where the last source was: p is reached when a source lies at
  // a walk distance in [lo, hi] behind it. Lines are walked side by side, a whole
  // slice across the axis at a time, so memory is read in order.
  auto walk = [&](std::size_t base, std::size_t count, std::size_t element_stride) {
    thread_local std::vector<std::int64_t> last;
    last.assign(count, std::numeric_limits<std::int64_t>::min() / 2);
    for (int step = 0; step < n; ++step) {
      const int src = step - lo;
      const int p = sign > 0 ? step : n - 1 - step;
      const float* source = nullptr;
      if (src >= 0 && src < n) source = mask.values.data() + base + std::size_t(sign > 0 ? src : n - 1 - src) * stride;
      std::uint8_t* target = out.values.data() + base + std::size_t(p) * stride;
      for (std::size_t i = 0; i < count; ++i) {
        if (source && double(source[i * element_stride]) <= r2) last[i] = src;
        if (step - last[i] <= hi) target[i * element_stride] = 1;
      }
    }
  };
  if (axis == Axis::X) {
    mask.for_each_line(axis, [&](std::size_t first) { walk(first, 1, 1); });
  } else if (axis == Axis::Y) {
    // One z slice at a time: rows of x are contiguous.
    tbb::parallel_for(tbb::blocked_range<int>(0, mask.nz), [&](const tbb::blocked_range<int>& r) {
      for (int z = r.begin(); z != r.end(); ++z) walk(mask.index(0, 0, z), std::size_t(mask.nx), 1);
    });
  } else {
    // Slices across Z are whole xy planes; split them into strips of rows.
    const int rows_per_strip = 8;
    tbb::parallel_for(tbb::blocked_range<int>(0, (mask.ny + rows_per_strip - 1) / rows_per_strip),
                      [&](const tbb::blocked_range<int>& r) {
                        for (int strip = r.begin(); strip != r.end(); ++strip) {
                          const int y0 = strip * rows_per_strip, y1 = std::min(mask.ny, y0 + rows_per_strip);
                          walk(mask.index(0, y0, 0), std::size_t(y1 - y0) * std::size_t(mask.nx), 1);
                        }
                      });
  }
}

Solid solid_from_bytes(const DenseGrid<std::uint8_t>& g, const Lattice& lattice, const IndexBox& domain) {
  return solid_where(g, [](std::uint8_t v) { return v != 0; }, lattice, domain);
}

}  // namespace

double widest_radius_sq(const AxialLevels& levels) {
  double widest = levels.tail_radius_sq;
  for (double r2 : levels.radius_sq) widest = std::max(widest, r2);
  return widest;
}

// Squared distances across `axis` (in the planes it is normal to) to the solid, up to
// `widest`: what every axial body along that axis needs, so bodies share it.
DenseGrid<float> distance_across(const Solid& solid, Axis axis, const IndexBox& work, double widest) {
  DenseGrid<float> perp = distance_seed<float>(solid, work);
  bool first_pass = true;
  for (Axis other : {Axis::X, Axis::Y, Axis::Z}) {
    if (other == axis) continue;
    distance_pass(perp, other, 1.0, widest, first_pass);
    first_pass = false;
  }
  return perp;
}

namespace {

// When levels 0..c of a body are exactly a hemisphere of radius c voxels centred at
// level c, and the levels above hold the ball's upper half (a ball-end cutter's flutes),
// returns c: the tip is then the whole ball. 0 otherwise.
int ball_tip_levels(const AxialLevels& levels) {
  const int n = int(levels.radius_sq.size());
  if (n == 0 || levels.radius_sq[0] != 0) return 0;
  int c = 0;
  while (c + 1 < n && levels.radius_sq[std::size_t(c) + 1] > levels.radius_sq[std::size_t(c)]) ++c;
  if (c < 2) return 0;
  auto level_sq = [&](int t) {
    if (t < n) return levels.radius_sq[std::size_t(t)];
    return levels.tail_from >= 0 && t >= levels.tail_from ? levels.tail_radius_sq : -1.0;
  };
  for (int t = 0; t <= 2 * c; ++t) {
    const double ball = double(c) * double(c) - double(t - c) * double(t - c);
    if (t <= c ? level_sq(t) != ball : level_sq(t) < ball) return 0;
  }
  return c;
}

}  // namespace

// The dilation by an axial body from the distances across its axis: level t of the body
// with radius r_t reaches p when the solid comes within r_t of p - t * direction.
Solid sweep_axial(const DenseGrid<float>& perp, const AxialBody& body, const Lattice& lattice, const IndexBox& domain) {
  const AxialLevels levels = axial_levels(body, lattice.voxel_size);
  const Axis a = body.direction.axis;
  DenseGrid<std::uint8_t> result(perp.box, 0);
  // A ball-end tip: its levels are a whole ball's, which one more distance pass along the
  // axis gives at once instead of one sweep per level.
  const int tip = ball_tip_levels(levels);
  if (tip > 0) {
    // The ball's centres lie `tip` levels along the body from the voxels it reaches, so
    // the grid reaches `tip` levels further back.
    const int shift = body.direction.sign * tip;
    IndexBox box = perp.box;
    Index3 lo = box.lo, hi = box.hi;
    if (shift > 0) component(lo, a) -= shift; else component(hi, a) -= shift;
    box = {lo, hi};
    DenseGrid<float> ball(box, std::numeric_limits<float>::infinity());
    const Index3 off{perp.box.lo.x - box.lo.x, perp.box.lo.y - box.lo.y, perp.box.lo.z - box.lo.z};
    tbb::parallel_for(tbb::blocked_range<int>(0, perp.nz), [&](const tbb::blocked_range<int>& r) {
      for (int z = r.begin(); z != r.end(); ++z)
        for (int y = 0; y < perp.ny; ++y)
          std::copy_n(perp.values.data() + perp.index(0, y, z), perp.nx, ball.values.data() + ball.index(off.x, y + off.y, z + off.z));
    });
    const double r2 = double(tip) * double(tip);
    distance_pass(ball, a, 1.0, r2, false);
    // Voxel p (grid of perp) is reached when the ball grid at p - shift is within r.
    tbb::parallel_for(tbb::blocked_range<int>(0, perp.nz), [&](const tbb::blocked_range<int>& r) {
      for (int z = r.begin(); z != r.end(); ++z)
        for (int y = 0; y < perp.ny; ++y)
          for (int x = 0; x < perp.nx; ++x) {
            Index3 src{x + off.x, y + off.y, z + off.z};
            component(src, a) -= shift;
            if (double(ball.values[ball.index(src.x, src.y, src.z)]) <= r2) result.values[result.index(x, y, z)] = 1;
          }
    });
  }
  // Group levels of equal radius into runs [lo, hi] so each radius is thresholded once.
  std::map<double, std::vector<std::pair<int, std::int64_t>>> runs;
  const int n = int(levels.radius_sq.size());
  for (int t = tip; t < n;) {
    const double r2 = levels.radius_sq[std::size_t(t)];
    int end = t;
    while (end + 1 < n && levels.radius_sq[std::size_t(end) + 1] == r2) ++end;
    std::int64_t hi = end;
    if (end == n - 1 && levels.tail_from >= 0 && r2 == levels.tail_radius_sq) hi = kUnboundedExtent;
    if (r2 >= 0) runs[r2].push_back({t, hi});
    t = end + 1;
  }
  if (levels.tail_from >= 0 && (n == 0 || levels.radius_sq.back() != levels.tail_radius_sq) &&
      levels.tail_radius_sq >= 0) {
    runs[levels.tail_radius_sq].push_back({std::max(n, levels.tail_from), kUnboundedExtent});
  }

  for (const auto& [r2, intervals] : runs)
    for (const auto& [lo, hi] : intervals) axial_dilate(perp, r2, result, a, body.direction.sign, lo, hi);
  return solid_from_bytes(result, lattice, domain);
}

Solid dilate_axial(const Solid& solid, const AxialBody& body, const IndexBox& work, const IndexBox& domain) {
  const AxialLevels levels = axial_levels(body, solid.voxel_size());
  const DenseGrid<float> perp = distance_across(solid, body.direction.axis, work, widest_radius_sq(levels));
  return sweep_axial(perp, body, solid.lattice(), domain);
}

}  // namespace hybridctl::geometry::detail
