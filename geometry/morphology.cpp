#include "geometry/morphology.hpp"

#include <fftw3.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <map>
#include <mutex>
#include <stdexcept>

namespace hybridctl::geometry {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Section ends are compared with this slack so that 30 mm at 0.1 mm voxels is level 300.
constexpr double kLengthSlack = 1e-9;

int& component(Index3& v, Axis a) { return a == Axis::X ? v.x : a == Axis::Y ? v.y : v.z; }

std::int64_t clamp_extent(std::int64_t v) {
  return std::clamp<std::int64_t>(v, -kUnboundedExtent, kUnboundedExtent);
}

// Large scratch buffers are kept for the next call: on these machines first-touch page
// faults cost more than the transforms themselves (about 2 s per GB). At most a few
// buffers of each type are kept.
template <typename T>
class BufferPool {
 public:
  static BufferPool& instance() {
    static BufferPool pool;
    return pool;
  }
  std::vector<T> take(std::size_t n, T fill) {
    std::vector<T> v;
    {
      std::lock_guard lock(mutex_);
      // The smallest kept buffer that is big enough, else the biggest.
      auto best = free_.end();
      for (auto it = free_.begin(); it != free_.end(); ++it) {
        if (best == free_.end()) {
          best = it;
          continue;
        }
        const bool fits = it->capacity() >= n, best_fits = best->capacity() >= n;
        if ((fits && (!best_fits || it->capacity() < best->capacity())) || (!fits && !best_fits && it->capacity() > best->capacity()))
          best = it;
      }
      if (best != free_.end()) {
        v = std::move(*best);
        free_.erase(best);
      }
    }
    v.assign(n, fill);
    return v;
  }
  void give(std::vector<T>&& v) {
    if (v.capacity() == 0) return;
    std::lock_guard lock(mutex_);
    if (free_.size() < kKept) free_.push_back(std::move(v));
  }

 private:
  static constexpr std::size_t kKept = 3;
  std::mutex mutex_;
  std::vector<std::vector<T>> free_;
};

// A dense box of values, x fastest.
template <typename T>
struct DenseGrid {
  IndexBox box;
  int nx = 0, ny = 0, nz = 0;
  std::vector<T> values;

  DenseGrid(IndexBox b, T fill) : box(b) {
    if (!b.empty()) {
      nx = b.hi.x - b.lo.x;
      ny = b.hi.y - b.lo.y;
      nz = b.hi.z - b.lo.z;
    }
    values = BufferPool<T>::instance().take(std::size_t(nx) * std::size_t(ny) * std::size_t(nz), fill);
  }
  DenseGrid(DenseGrid&&) = default;
  DenseGrid& operator=(DenseGrid&&) = default;
  ~DenseGrid() { BufferPool<T>::instance().give(std::move(values)); }
  std::size_t index(int x, int y, int z) const {  // grid-relative coordinates
    return (std::size_t(z) * std::size_t(ny) + std::size_t(y)) * std::size_t(nx) + std::size_t(x);
  }
  int size(Axis a) const { return a == Axis::X ? nx : a == Axis::Y ? ny : nz; }
  std::size_t stride(Axis a) const {
    return a == Axis::X ? 1 : a == Axis::Y ? std::size_t(nx) : std::size_t(nx) * std::size_t(ny);
  }
  // Calls fn(first_index) for every line along `a`, in parallel.
  template <typename Fn>
  void for_each_line(Axis a, Fn fn) const {
    for_each_line_block(a, [&](std::size_t first, int count) {
      for (int j = 0; j < count; ++j) fn(first + std::size_t(j));
    });
  }
  // Calls fn(first_index, count) for blocks of up to kBlock lines along `a` (a != X)
  // that are neighbours along X, so a gather touches whole cache lines; along X every
  // block is one contiguous line.
  static constexpr int kBlock = 8;
  template <typename Fn>
  void for_each_line_block(Axis a, Fn fn) const {
    const Axis u = a == Axis::X ? Axis::Y : Axis::X;
    const Axis v = a == Axis::Z ? Axis::Y : Axis::Z;
    const int nu = size(u), nv = size(v);
    const std::size_t su = stride(u), sv = stride(v);
    const int step = a == Axis::X ? 1 : kBlock;
    tbb::parallel_for(tbb::blocked_range<int>(0, nv), [&](const tbb::blocked_range<int>& r) {
      for (int j = r.begin(); j != r.end(); ++j)
        for (int i = 0; i < nu; i += step) fn(std::size_t(i) * su + std::size_t(j) * sv, std::min(step, nu - i));
    });
  }
};

// 0 on the solid's voxels, infinity elsewhere. Squared distances in whole voxels (balls,
// axial bodies) are integers that float holds exactly up to 2^24 (a radius of 4096
// voxels), at half the memory traffic of double; ellipsoids' scaled ones need double.
template <typename T>
DenseGrid<T> distance_seed(const Solid& solid, const IndexBox& box) {
  DenseGrid<T> g(box, std::numeric_limits<T>::infinity());
  const IndexBox inside = box_intersection(box, solid.bounding_box());
  if (inside.empty()) return g;
  tbb::parallel_for(tbb::blocked_range<int>(inside.lo.z, inside.hi.z), [&](const tbb::blocked_range<int>& r) {
    for (int z = r.begin(); z != r.end(); ++z)
      for (int y = inside.lo.y; y < inside.hi.y; ++y) {
        T* line = g.values.data() + g.index(0, y - box.lo.y, z - box.lo.z) - box.lo.x;  // indexed by x
        for (int w = inside.lo.x >> 6; w <= (inside.hi.x - 1) >> 6; ++w)
          for (std::uint64_t bits = solid.word_at(w, y, z); bits; bits &= bits - 1) {
            const int x = w * 64 + std::countr_zero(bits);
            if (x >= inside.lo.x && x < inside.hi.x) line[x] = 0;
          }
      }
  });
  return g;
}

// The lower envelope of parabolas f(q) + w (p - q)^2 over one line (Felzenszwalb &
// Huttenlocher), written back to `f`. Exact minimum of the computed expressions: at
// each p the neighbouring parabolas of the envelope are checked too. Values above
// `limit` become infinity: later passes only add to them and the caller thresholds.
template <typename T>
void envelope(T* f, int n, double w, double limit, std::vector<double>& z, std::vector<int>& v, std::vector<T>& out) {
  z.resize(std::size_t(n) + 1);
  v.resize(std::size_t(n));
  out.resize(std::size_t(n));
  int k = -1;
  for (int q = 0; q < n; ++q) {
    if (f[q] == kInf) continue;
    if (k < 0) {
      k = 0;
      v[0] = q;
      z[0] = -kInf;
      z[1] = kInf;
      continue;
    }
    double s;
    while (true) {
      const int p = v[std::size_t(k)];
      s = ((double(f[q]) + w * double(q) * double(q)) - (double(f[p]) + w * double(p) * double(p))) / (2.0 * w * double(q - p));
      if (s <= z[std::size_t(k)] && k > 0) {
        --k;
      } else {
        break;
      }
    }
    ++k;
    v[std::size_t(k)] = q;
    z[std::size_t(k)] = s;
    z[std::size_t(k) + 1] = kInf;
  }
  if (k < 0) return;  // nothing finite on this line
  int j = 0;
  for (int p = 0; p < n; ++p) {
    while (z[std::size_t(j) + 1] < double(p)) ++j;
    auto value = [&](int site) { return double(f[site]) + w * double((p - site) * (p - site)); };
    double best = value(v[std::size_t(j)]);
    if (j > 0) best = std::min(best, value(v[std::size_t(j) - 1]));
    if (j < k) best = std::min(best, value(v[std::size_t(j) + 1]));
    out[std::size_t(p)] = best <= limit ? T(best) : std::numeric_limits<T>::infinity();
  }
  std::copy(out.begin(), out.begin() + n, f);
}

// First pass over seeds (0 on the solid, infinity elsewhere): the distance to the
// nearest seed on the line, by a sweep each way. Returns false when nothing changed.
template <typename T>
bool seed_distances(T* f, int n, double w, double limit, std::vector<int>& nearest) {
  nearest.assign(std::size_t(n), -1);
  int last = -1;
  bool any_seed = false, any_gap = false;
  for (int p = 0; p < n; ++p) {
    if (f[p] == 0) {
      last = p;
      any_seed = true;
    } else {
      any_gap = true;
    }
    nearest[std::size_t(p)] = last;
  }
  if (!any_seed || !any_gap) return false;  // all air or all material: nothing moves
  last = -1;
  for (int p = n - 1; p >= 0; --p) {
    if (f[p] == 0) last = p;
    int d = INT32_MAX;
    if (nearest[std::size_t(p)] >= 0) d = p - nearest[std::size_t(p)];
    if (last >= 0) d = std::min(d, last - p);
    const double value = w * double(d) * double(d);
    f[p] = value <= limit ? T(value) : std::numeric_limits<T>::infinity();
  }
  return true;
}

// One pass of the separable distance transform along `axis`:
// f(p) <- min_q f(q) + w (p - q)^2. `seeds` says the grid still holds only 0 and
// infinity (the first pass).
template <typename T>
void distance_pass(DenseGrid<T>& g, Axis axis, double w, double limit, bool seeds) {
  const int n = g.size(axis);
  const std::size_t stride = g.stride(axis);
  g.for_each_line_block(axis, [&](std::size_t first, int count) {
    thread_local std::vector<T> buffer, out;
    thread_local std::vector<double> z;
    thread_local std::vector<int> v;
    buffer.resize(std::size_t(n) * std::size_t(count));
    // Gather `count` neighbouring lines (one cache line per step), transform, scatter.
    for (int q = 0; q < n; ++q)
      for (int j = 0; j < count; ++j)
        buffer[std::size_t(j) * std::size_t(n) + std::size_t(q)] = g.values[first + std::size_t(q) * stride + std::size_t(j)];
    bool changed = false;
    for (int j = 0; j < count; ++j) {
      T* line = buffer.data() + std::size_t(j) * std::size_t(n);
      if (seeds) {
        changed |= seed_distances(line, n, w, limit, v);
        continue;
      }
      // Lines wholly inside (all zero) or wholly outside (all infinite) stay as they are.
      bool all_zero = true, all_inf = true;
      for (int q = 0; q < n && (all_zero || all_inf); ++q) {
        all_zero = all_zero && line[q] == 0;
        all_inf = all_inf && line[q] == std::numeric_limits<T>::infinity();
      }
      if (all_zero || all_inf) continue;
      envelope(line, n, w, limit, z, v, out);
      changed = true;
    }
    if (!changed) return;
    for (int q = 0; q < n; ++q)
      for (int j = 0; j < count; ++j)
        g.values[first + std::size_t(q) * stride + std::size_t(j)] = buffer[std::size_t(j) * std::size_t(n) + std::size_t(q)];
  });
}

// The voxels of `domain` whose grid value satisfies `keep`, copied into a solid a word
// at a time.
template <typename T, typename Keep>
Solid solid_where(const DenseGrid<T>& g, Keep keep, const Lattice& lattice, const IndexBox& domain) {
  Solid out(lattice, domain);
  const IndexBox b = box_intersection(domain, g.box);
  if (b.empty()) return out;
  tbb::parallel_for(tbb::blocked_range<int>(b.lo.z, b.hi.z), [&](const tbb::blocked_range<int>& r) {
    for (int z = r.begin(); z != r.end(); ++z)
      for (int y = b.lo.y; y < b.hi.y; ++y) {
        auto row = out.row(y, z);
        const T* line = g.values.data() + g.index(0, y - g.box.lo.y, z - g.box.lo.z) - g.box.lo.x;
        for (int x = b.lo.x; x < b.hi.x; ++x)
          if (keep(line[x])) row[std::size_t((x >> 6) - out.first_word())] |= std::uint64_t{1} << (x & 63);
      }
  });
  return out;
}

template <typename T>
Solid threshold_into(const DenseGrid<T>& g, double limit, const Lattice& lattice, const IndexBox& domain) {
  return solid_where(g, [limit](T v) { return double(v) <= limit; }, lattice, domain);
}

// The radius squared (in voxels^2) of an axial body at each level t along its axis.
struct AxialLevels {
  std::vector<double> radius_sq;  // levels 0..n-1; negative: empty level
  int tail_from = -1;             // an infinite tail from this level on, or -1
  double tail_radius_sq = -1;
};

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

Solid dilate_brute_force(const Solid& solid, const std::vector<Index3>& offsets, const IndexBox& domain) {
  Solid out(solid.lattice(), domain);
  solid.for_each_voxel([&](Index3 s) {
    for (const Index3& d : offsets) {
      const Index3 p{s.x + d.x, s.y + d.y, s.z + d.z};
      if (domain.contains(p)) out.set(p);
    }
  });
  return out;
}

// The Minkowski sum as a union of shifted copies, 64 voxels a word: offsets with the
// same (dy, dz) share one pass over each source row. Cost ~ offsets x occupied rows x
// words per row, which beats the distance transforms for small beads and balls.
Solid dilate_shifts(const Solid& solid, const std::vector<Index3>& offsets, const IndexBox& source, const IndexBox& domain) {
  Solid out(solid.lattice(), domain);
  if (offsets.empty() || source.empty()) return out;
  std::map<std::pair<int, int>, std::vector<int>> by_row;  // (dy, dz) -> dx values
  for (const Index3& d : offsets) by_row[{d.y, d.z}].push_back(d.x);
  const IndexBox store = solid.storage_box();
  const int sw0 = solid.first_word(), swn = solid.words_per_row();
  const int ow0 = out.first_word(), own = out.words_per_row();
  // Which source rows hold anything, so empty space costs nothing.
  const int sy0 = source.lo.y, sny = source.hi.y - source.lo.y, snz = source.hi.z - source.lo.z;
  std::vector<std::uint8_t> occupied(std::size_t(sny) * std::size_t(snz), 0);
  tbb::parallel_for(tbb::blocked_range<int>(0, snz), [&](const tbb::blocked_range<int>& r) {
    for (int k = r.begin(); k != r.end(); ++k)
      for (int j = 0; j < sny; ++j) {
        const int y = sy0 + j, z = source.lo.z + k;
        if (y < store.lo.y || y >= store.hi.y || z < store.lo.z || z >= store.hi.z) continue;
        for (std::uint64_t w : solid.row(y, z))
          if (w) {
            occupied[std::size_t(k) * std::size_t(sny) + std::size_t(j)] = 1;
            break;
          }
      }
  });
  tbb::parallel_for(tbb::blocked_range<int>(domain.lo.z, domain.hi.z), [&](const tbb::blocked_range<int>& r) {
    for (int z = r.begin(); z != r.end(); ++z)
      for (int y = domain.lo.y; y < domain.hi.y; ++y) {
        auto dst = out.row(y, z);
        for (const auto& [dyz, dxs] : by_row) {
          const int ys = y - dyz.first, zs = z - dyz.second;
          if (ys < source.lo.y || ys >= source.hi.y || zs < source.lo.z || zs >= source.hi.z) continue;
          if (!occupied[std::size_t(zs - source.lo.z) * std::size_t(sny) + std::size_t(ys - sy0)]) continue;
          const auto src = solid.row(ys, zs);
          for (int dx : dxs) {
            // Output voxel x takes source voxel x - dx.
            const int q = dx >= 0 ? dx / 64 : -((-dx + 63) / 64);
            const int rbits = dx - q * 64;  // 0..63
            for (int w = 0; w < own; ++w) {
              const int sword = ow0 + w - q - sw0;  // index into src of the word shifted up by rbits
              std::uint64_t v = 0;
              if (sword >= 0 && sword < swn) v = src[std::size_t(sword)] << rbits;
              if (rbits && sword - 1 >= 0 && sword - 1 < swn) v |= src[std::size_t(sword - 1)] >> (64 - rbits);
              dst[std::size_t(w)] |= v;
            }
          }
        }
      }
  });
  // Shifts may reach past the domain inside the last word; clip.
  return intersect(out, Solid::filled(solid.lattice(), domain));
}

std::mutex fftw_planner_mutex;  // FFTW's planner is not thread-safe

Solid dilate_fft(const Solid& solid, const std::vector<Index3>& offsets, const IndexBox& source, const IndexBox& domain) {
  Solid out(solid.lattice(), domain);
  if (source.empty() || offsets.empty()) return out;
  IndexBox ext{{INT32_MAX, INT32_MAX, INT32_MAX}, {INT32_MIN, INT32_MIN, INT32_MIN}};
  for (const Index3& d : offsets) {
    ext.lo = {std::min(ext.lo.x, d.x), std::min(ext.lo.y, d.y), std::min(ext.lo.z, d.z)};
    ext.hi = {std::max(ext.hi.x, d.x + 1), std::max(ext.hi.y, d.y + 1), std::max(ext.hi.z, d.z + 1)};
  }
  // Linear (not cyclic) convolution: pad each axis to source + element - 1.
  const int nx = (source.hi.x - source.lo.x) + (ext.hi.x - ext.lo.x) - 1;
  const int ny = (source.hi.y - source.lo.y) + (ext.hi.y - ext.lo.y) - 1;
  const int nz = (source.hi.z - source.lo.z) + (ext.hi.z - ext.lo.z) - 1;
  const std::size_t real_size = std::size_t(nx) * std::size_t(ny) * std::size_t(nz);
  const std::size_t complex_size = std::size_t(nz) * std::size_t(ny) * std::size_t(nx / 2 + 1);
  std::vector<double> a(real_size, 0.0), b(real_size, 0.0);
  auto at = [&](int x, int y, int z) { return (std::size_t(z) * std::size_t(ny) + std::size_t(y)) * std::size_t(nx) + std::size_t(x); };
  solid.for_each_voxel([&](Index3 s) {
    if (source.contains(s)) a[at(s.x - source.lo.x, s.y - source.lo.y, s.z - source.lo.z)] = 1.0;
  });
  for (const Index3& d : offsets) b[at(d.x - ext.lo.x, d.y - ext.lo.y, d.z - ext.lo.z)] = 1.0;
  fftw_complex* fa = fftw_alloc_complex(complex_size);
  fftw_complex* fb = fftw_alloc_complex(complex_size);
  fftw_plan forward_a, forward_b, backward;
  {
    std::lock_guard lock(fftw_planner_mutex);
    forward_a = fftw_plan_dft_r2c_3d(nz, ny, nx, a.data(), fa, FFTW_ESTIMATE);
    forward_b = fftw_plan_dft_r2c_3d(nz, ny, nx, b.data(), fb, FFTW_ESTIMATE);
    backward = fftw_plan_dft_c2r_3d(nz, ny, nx, fa, a.data(), FFTW_ESTIMATE);
  }
  fftw_execute(forward_a);
  fftw_execute(forward_b);
  for (std::size_t i = 0; i < complex_size; ++i) {
    const double re = fa[i][0] * fb[i][0] - fa[i][1] * fb[i][1];
    const double im = fa[i][0] * fb[i][1] + fa[i][1] * fb[i][0];
    fa[i][0] = re;
    fa[i][1] = im;
  }
  fftw_execute(backward);
  {
    std::lock_guard lock(fftw_planner_mutex);
    fftw_destroy_plan(forward_a);
    fftw_destroy_plan(forward_b);
    fftw_destroy_plan(backward);
  }
  fftw_free(fa);
  fftw_free(fb);
  // A count of overlapping voxels, scaled by the transform size; half a voxel decides.
  const double scale = double(real_size);
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < ny; ++y)
      for (int x = 0; x < nx; ++x) {
        if (a[at(x, y, z)] / scale <= 0.5) continue;
        const Index3 p{source.lo.x + ext.lo.x + x, source.lo.y + ext.lo.y + y, source.lo.z + ext.lo.z + z};
        if (domain.contains(p)) out.set(p);
      }
  return out;
}

bool is_finite_extent(const IndexBox& e) {
  return e.lo.x > -kUnboundedExtent && e.lo.y > -kUnboundedExtent && e.lo.z > -kUnboundedExtent &&
         e.hi.x < kUnboundedExtent && e.hi.y < kUnboundedExtent && e.hi.z < kUnboundedExtent;
}

IndexBox grow(const IndexBox& b, const IndexBox& ext) {
  return {{int(clamp_extent(std::int64_t(b.lo.x) + ext.lo.x)), int(clamp_extent(std::int64_t(b.lo.y) + ext.lo.y)),
           int(clamp_extent(std::int64_t(b.lo.z) + ext.lo.z))},
          {int(clamp_extent(std::int64_t(b.hi.x) + ext.hi.x - 1)), int(clamp_extent(std::int64_t(b.hi.y) + ext.hi.y - 1)),
           int(clamp_extent(std::int64_t(b.hi.z) + ext.hi.z - 1))}};
}

}  // namespace

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
