// Tool sweeps (morphology.hpp, tool_sweeps): where a cutting part B reaches while its
// clearance D misses the solid, (complement of S (+) -D) (+) B.
//
// Why columns. Let u count voxels along the tool's direction e (from the tip towards its
// holder) and c be a column, a line along e. A tip at (c, u) collides when some level t
// of D (a disc of radius r(t) across the axis) meets the solid: perp(c, u + t) <= r(t)^2,
// with perp the squared distance to the solid within its slice across the axis. When
// r(t) never decreases and D never ends (a cutter, its shank and a holder that goes on),
// a collision at u is also one at u - 1 (level t + 1 reaches the same slice), so the free
// tips of a column are one ray u >= h(c): a heightmap. Then
//   h(c) = 1 + max over slices u of (u - tmin(perp(c, u))), tmin(d) = first t with r(t)^2 >= d,
// and a voxel q = (c, u) is swept when some level t of B and some column c' within its
// radius have u - t >= h(c'):  u >= min over t of (min over the disc of h) + t.
// Only the levels where a body first widens matter (narrower later levels are dominated),
// and the slices' distances across the axis are shared by every tool along that axis.
// The heightmaps are 2-D, so a tool costs a scan of one shared grid and a few
// disc-minimum filters instead of two distance transforms and sweeps over 3-D grids.

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <stdexcept>

#include "geometry/morphology_internal.hpp"
#include "geometry/sliding_extremum.hpp"

namespace hybridctl::geometry {

using namespace detail;

namespace {

// "No collision in this column": far below any height, with room to add levels.
constexpr std::int32_t kNoHeight = -(1 << 29);

int coordinate(const Index3& p, Axis a) { return a == Axis::X ? p.x : a == Axis::Y ? p.y : p.z; }
// The axes across `a`, as offsets_of orders them.
Axis across_u(Axis a) { return a == Axis::X ? Axis::Y : Axis::X; }
Axis across_v(Axis a) { return a == Axis::Z ? Axis::Y : Axis::Z; }

// The radius squared of a body's level t, past the stored levels too.
double level_at(const AxialLevels& l, std::int64_t t) {
  if (t < std::int64_t(l.radius_sq.size())) return l.radius_sq[std::size_t(t)];
  return l.tail_from >= 0 ? l.tail_radius_sq : -1.0;
}

// The levels of a union of bodies along one axis and direction: the widest disc per level.
// No bodies: the tip alone (one level of radius 0).
AxialLevels union_levels(const std::vector<AxialBody>& bodies, double h) {
  if (bodies.empty()) return AxialLevels{{0.0}, -1, -1};
  std::vector<AxialLevels> parts;
  std::size_t size = 0;
  for (const AxialBody& b : bodies) {
    parts.push_back(axial_levels(b, h));
    size = std::max(size, parts.back().radius_sq.size());
  }
  AxialLevels u;
  u.radius_sq.assign(size, -1.0);
  for (const AxialLevels& p : parts) {
    for (std::size_t t = 0; t < size; ++t) u.radius_sq[t] = std::max(u.radius_sq[t], level_at(p, std::int64_t(t)));
    if (p.tail_from >= 0) {
      u.tail_from = int(size);
      u.tail_radius_sq = std::max(u.tail_radius_sq, p.tail_radius_sq);
    }
  }
  return u;
}

// Free tips form one ray per column: the body never narrows away from the tip and never ends.
bool one_ray_per_column(const AxialLevels& l) {
  if (l.tail_from < 0) return false;
  for (std::size_t t = 1; t < l.radius_sq.size(); ++t)
    if (l.radius_sq[t] < l.radius_sq[t - 1]) return false;
  return l.radius_sq.empty() || l.tail_radius_sq >= l.radius_sq.back();
}

// A level at which the body reaches a radius wider than every level before it.
struct Widening {
  std::int64_t level;
  double radius_sq;
};

std::vector<Widening> widenings(const AxialLevels& l) {
  std::vector<Widening> out;
  const std::int64_t n = std::int64_t(l.radius_sq.size()) + (l.tail_from >= 0 ? 1 : 0);
  for (std::int64_t t = 0; t < n; ++t) {
    const double r2 = level_at(l, t);
    if (r2 >= 0 && (out.empty() || r2 > out.back().radius_sq)) out.push_back({t, r2});
  }
  return out;
}

// The largest whole number of voxels n with n^2 <= r2 (offsets_of's test, in doubles).
int whole_radius(double r2) {
  if (r2 < 0) return -1;
  int n = int(std::floor(std::sqrt(r2)));
  while (double(n + 1) * double(n + 1) <= r2) ++n;
  while (n > 0 && double(n) * double(n) > r2) --n;
  return n;
}

// A rectangle of columns across the axis, row-major in v.
struct Columns {
  int u0 = 0, u1 = 0, v0 = 0, v1 = 0;
  int width() const { return u1 - u0; }
  int height() const { return v1 - v0; }
  std::size_t size() const { return std::size_t(width()) * std::size_t(height()); }
  std::size_t index(int u, int v) const { return std::size_t(v - v0) * std::size_t(width()) + std::size_t(u - u0); }
  bool contains(int u, int v) const { return u >= u0 && u < u1 && v >= v0 && v < v1; }
};

Columns columns_of(const IndexBox& b, Axis a) {
  const Axis u = across_u(a), v = across_v(a);
  return {coordinate(b.lo, u), coordinate(b.hi, u), coordinate(b.lo, v), coordinate(b.hi, v)};
}

// What one sweep needs, in the group's terms.
struct ColumnSweep {
  std::size_t request;
  int sign;
  std::vector<Widening> clearance;
  std::vector<std::size_t> bucket;  // per clearance widening: its radius among the group's
  std::vector<Widening> cutting;
};

// Per column and per radius of the group (ascending), the highest and lowest slice
// coordinate along the axis where the solid lies within that radius across it; after
// `prefix`, within that radius or any smaller one.
struct Reach {
  Columns cols;
  std::vector<double> radii;
  std::vector<std::int32_t> low, high;  // [radius][column]
  std::int32_t& lo(std::size_t r, std::size_t c) { return low[r * cols.size() + c]; }
  std::int32_t& hi(std::size_t r, std::size_t c) { return high[r * cols.size() + c]; }
};

Reach scan_reach(const Solid& solid, Axis a, const Columns& q, std::vector<double> radii) {
  Reach reach{q, std::move(radii), {}, {}};
  const std::size_t cells = reach.radii.size() * q.size();
  reach.low.assign(cells, -kNoHeight);
  reach.high.assign(cells, kNoHeight);
  const IndexBox sb = solid.bounding_box();
  if (sb.empty() || reach.radii.empty()) return reach;
  // The distances across the axis, over the solid's slices and every column it can reach.
  const Columns sc = columns_of(sb, a);
  const Columns pc{std::min(q.u0, sc.u0), std::max(q.u1, sc.u1), std::min(q.v0, sc.v0), std::max(q.v1, sc.v1)};
  IndexBox work = sb;
  const Axis au = across_u(a), av = across_v(a);
  auto set = [](Index3& p, Axis ax, int value) { (ax == Axis::X ? p.x : ax == Axis::Y ? p.y : p.z) = value; };
  set(work.lo, au, pc.u0);
  set(work.hi, au, pc.u1);
  set(work.lo, av, pc.v0);
  set(work.hi, av, pc.v1);
  const double widest = reach.radii.back();
  const DenseGrid<float> perp = distance_across(solid, a, work, widest);
  // Distance d (a whole number of voxels squared) -> the first radius that holds it.
  std::vector<std::int32_t> radius_of(std::size_t(std::floor(widest)) + 1);
  for (std::size_t d = 0; d < radius_of.size(); ++d)
    radius_of[d] = std::int32_t(std::lower_bound(reach.radii.begin(), reach.radii.end(), double(d)) - reach.radii.begin());
  // Threads split the grid along v, so each owns its columns.
  const int nv = a == Axis::Z ? perp.ny : perp.nz;
  tbb::parallel_for(tbb::blocked_range<int>(0, nv), [&](const tbb::blocked_range<int>& r) {
    const int z0 = a == Axis::Z ? 0 : r.begin(), z1 = a == Axis::Z ? perp.nz : r.end();
    const int y0 = a == Axis::Z ? r.begin() : 0, y1 = a == Axis::Z ? r.end() : perp.ny;
    for (int z = z0; z < z1; ++z)
      for (int y = y0; y < y1; ++y) {
        const float* line = perp.values.data() + perp.index(0, y, z);
        for (int x = 0; x < perp.nx; ++x) {
          if (line[x] == std::numeric_limits<float>::infinity()) continue;
          const Index3 p{perp.box.lo.x + x, perp.box.lo.y + y, perp.box.lo.z + z};
          const int u = coordinate(p, au), v = coordinate(p, av), w = coordinate(p, a);
          if (!q.contains(u, v)) continue;
          const std::size_t c = q.index(u, v), k = std::size_t(radius_of[std::size_t(line[x])]);
          reach.lo(k, c) = std::min(reach.lo(k, c), w);
          reach.hi(k, c) = std::max(reach.hi(k, c), w);
        }
      }
  });
  for (std::size_t k = 1; k < reach.radii.size(); ++k)
    for (std::size_t c = 0; c < q.size(); ++c) {
      reach.lo(k, c) = std::min(reach.lo(k, c), reach.lo(k - 1, c));
      reach.hi(k, c) = std::max(reach.hi(k, c), reach.hi(k - 1, c));
    }
  return reach;
}

// The lowest free tip height h(c) per column, in u = sign * coordinate.
std::vector<std::int32_t> free_heights(Reach& reach, const ColumnSweep& s) {
  std::vector<std::int32_t> h(reach.cols.size(), kNoHeight);
  for (std::size_t j = 0; j < s.clearance.size(); ++j) {
    const std::size_t k = s.bucket[j];
    const std::int64_t t = s.clearance[j].level;
    for (std::size_t c = 0; c < h.size(); ++c) {
      const std::int32_t top = s.sign > 0 ? reach.hi(k, c) : -reach.lo(k, c);
      if (top > kNoHeight) h[c] = std::max(h[c], std::int32_t(std::max<std::int64_t>(top - t + 1, kNoHeight)));
    }
  }
  return h;
}

// min over the disc of radius^2 r2 of `h` (on `q`), plus `add`, folded into `out` (on `d`).
void disc_minimum(const std::vector<std::int32_t>& h, const Columns& q, double r2, std::int64_t add, const Columns& d,
                  std::vector<std::int32_t>& out) {
  const int n = whole_radius(r2);
  tbb::parallel_for(tbb::blocked_range<int>(d.v0, d.v1), [&](const tbb::blocked_range<int>& rows) {
    std::vector<std::int32_t> forward(std::size_t(q.width())), backward(std::size_t(q.width()));
    for (int v = rows.begin(); v != rows.end(); ++v) {
      std::int32_t* o = out.data() + d.index(d.u0, v);
      for (int dv = -n; dv <= n; ++dv) {
        const int w = whole_radius(r2 - double(dv) * double(dv));
        const std::int32_t* in = h.data() + q.index(q.u0, v + dv);
        // The minimum over the row's window of 2w + 1 (geometry/sliding_extremum.hpp).
        const int k = 2 * w + 1;
        const auto smaller = [](std::int32_t a, std::int32_t b) { return std::min(a, b); };
        block_extrema(in, q.width(), k, forward.data(), backward.data(), smaller);
        for (int u = d.u0; u < d.u1; ++u) {
          const int i = u - q.u0;
          const std::int32_t m = window_extremum(forward.data(), backward.data(), i - w, k, smaller);
          const std::int32_t value = m <= kNoHeight ? kNoHeight : std::int32_t(std::int64_t(m) + add);
          o[u - d.u0] = std::min(o[u - d.u0], value);
        }
      }
    }
  });
}

// The voxels of `domain` at or above the swept height of their column (u = sign * the
// coordinate along `a`), a row of X at a time.
Solid solid_above(const std::vector<std::int32_t>& lowest, const Columns& d, Axis a, int sign, const Lattice& lattice,
                  const IndexBox& domain) {
  Solid out(lattice, domain);
  const int x0 = domain.lo.x, x1 = domain.hi.x;
  tbb::parallel_for(tbb::blocked_range<int>(domain.lo.z, domain.hi.z), [&](const tbb::blocked_range<int>& r) {
    for (int z = r.begin(); z != r.end(); ++z)
      for (int y = domain.lo.y; y < domain.hi.y; ++y) {
        if (a == Axis::X) {
          // The row is the column: one run.
          const std::int64_t from = lowest[d.index(y, z)];
          const std::int64_t lo = sign > 0 ? std::max<std::int64_t>(x0, from) : x0;
          const std::int64_t hi = sign > 0 ? x1 : std::min<std::int64_t>(x1, -from + 1);
          if (lo < hi) out.set_run(y, z, int(lo), int(hi));
          continue;
        }
        // Along Y the row's columns are (x, z), along Z (x, y): x runs along the heightmap.
        const std::int32_t u = sign * (a == Axis::Y ? y : z);
        const std::int32_t* from = lowest.data() + (a == Axis::Y ? d.index(x0, z) : d.index(x0, y)) - x0;  // by x
        auto words = out.row(y, z);
        for (int x = x0; x < x1;) {
          const int word = x >> 6, end = std::min(x1, (word + 1) * 64);
          std::uint64_t bits = 0;
          for (; x < end; ++x) bits |= std::uint64_t(u >= from[x]) << (x & 63);
          words[std::size_t(word - out.first_word())] |= bits;
        }
      }
  });
  return out;
}

// Every sweep along axis `a` whose clearance gives one ray per column.
void sweep_by_columns(const Solid& solid, const std::vector<ColumnSweep>& group, Axis a, const IndexBox& domain,
                      std::vector<Solid>& out, const std::function<void(std::size_t)>& done) {
  int reach_across = 0;
  std::vector<double> radii;
  for (const ColumnSweep& s : group) {
    reach_across = std::max(reach_across, whole_radius(s.cutting.back().radius_sq));
    for (const Widening& w : s.clearance) radii.push_back(w.radius_sq);
  }
  std::sort(radii.begin(), radii.end());
  radii.erase(std::unique(radii.begin(), radii.end()), radii.end());
  const Columns d = columns_of(domain, a);
  const Columns q{d.u0 - reach_across, d.u1 + reach_across, d.v0 - reach_across, d.v1 + reach_across};
  Reach reach = scan_reach(solid, a, q, radii);
  for (ColumnSweep s : group) {
    for (const Widening& w : s.clearance)
      s.bucket.push_back(std::size_t(std::lower_bound(radii.begin(), radii.end(), w.radius_sq) - radii.begin()));
    const std::vector<std::int32_t> h = free_heights(reach, s);
    std::vector<std::int32_t> lowest(d.size(), -kNoHeight);
    for (const Widening& w : s.cutting) disc_minimum(h, q, w.radius_sq, w.level, d, lowest);
    out[s.request] = solid_above(lowest, d, a, s.sign, solid.lattice(), domain);
    if (done) done(s.request);
  }
}

// Any clearance: the definition, with the clearance's dilations sharing their transforms.
Solid sweep_by_dilation(const Solid& solid, const ToolSweep& s, const IndexBox& domain) {
  const IndexBox ext = element_extent(reflected(s.cutting), solid.voxel_size());
  if (!is_finite_extent(ext)) throw std::invalid_argument("a tool sweep's cutting part must be finite unless its clearance never narrows");
  // Every tip position from which the cutting part can reach the domain.
  const IndexBox work = grow(domain, ext);
  Solid obstacle = intersect(solid, Solid::filled(solid.lattice(), work));
  if (!s.clearance.empty()) {
    std::vector<StructuringElement> elements;
    for (const AxialBody& c : s.clearance) elements.push_back(reflected(c));
    obstacle = Solid(solid.lattice(), work);
    for (const Solid& g : dilate_each(solid, elements, work)) obstacle = unite(obstacle, g);
  }
  return dilate(complement(obstacle, work), s.cutting, domain);
}

}  // namespace

std::vector<Solid> tool_sweeps(const Solid& solid, const std::vector<ToolSweep>& sweeps, const IndexBox& domain,
                               const std::function<void(std::size_t)>& done) {
  const double h = solid.voxel_size();
  std::vector<Solid> out(sweeps.size());
  std::vector<ColumnSweep> by_axis[3];
  for (std::size_t i = 0; i < sweeps.size(); ++i) {
    const ToolSweep& s = sweeps[i];
    for (const AxialBody& c : s.clearance)
      if (!(c.direction == s.cutting.direction))
        throw std::invalid_argument("a tool sweep's clearance must share its cutting part's axis and direction");
    const AxialLevels clearance = union_levels(s.clearance, h);
    const std::vector<Widening> cutting = widenings(axial_levels(s.cutting, h));
    if (domain.empty() || cutting.empty()) {
      out[i] = Solid(solid.lattice(), domain);
      if (done) done(i);
    } else if (one_ray_per_column(clearance)) {
      by_axis[int(s.cutting.direction.axis)].push_back({i, s.cutting.direction.sign, widenings(clearance), {}, cutting});
    } else {
      out[i] = sweep_by_dilation(solid, s, domain);
      if (done) done(i);
    }
  }
  for (Axis a : {Axis::X, Axis::Y, Axis::Z})
    if (!by_axis[int(a)].empty()) sweep_by_columns(solid, by_axis[int(a)], a, domain, out, done);
  return out;
}

}  // namespace hybridctl::geometry
