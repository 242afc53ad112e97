#pragma once
// Internal to the morphology (morphology*.cpp); nothing else includes it. The dense grids
// the algorithms work on, and the algorithms morphology.cpp chooses between:
//   morphology_distance.cpp  separable squared-distance transforms (Felzenszwalb & Huttenlocher)
//   morphology_axial.cpp     axial bodies: distances across the axis, then column sweeps along it
//   morphology_shifts.cpp    the union of shifted copies, 64 voxels a word; the brute-force sum
//   morphology_fft.cpp       convolution of indicator functions with FFTW
//   morphology_columns.cpp   tool sweeps: free tip positions per column, heightmaps

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <limits>
#include <mutex>
#include <vector>

#include "geometry/morphology.hpp"

namespace hybridctl::geometry::detail {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Section ends are compared with this slack so that 30 mm at 0.1 mm voxels is level 300.
constexpr double kLengthSlack = 1e-9;

inline int& component(Index3& v, Axis a) { return a == Axis::X ? v.x : a == Axis::Y ? v.y : v.z; }

inline std::int64_t clamp_extent(std::int64_t v) {
  return std::clamp<std::int64_t>(v, -kUnboundedExtent, kUnboundedExtent);
}

inline bool is_finite_extent(const IndexBox& e) {
  return e.lo.x > -kUnboundedExtent && e.lo.y > -kUnboundedExtent && e.lo.z > -kUnboundedExtent &&
         e.hi.x < kUnboundedExtent && e.hi.y < kUnboundedExtent && e.hi.z < kUnboundedExtent;
}

// The box `b` grown by an element's extent `ext` (half-open, as element_extent gives it):
// every voxel of b plus every offset of the element.
inline IndexBox grow(const IndexBox& b, const IndexBox& ext) {
  return {{int(clamp_extent(std::int64_t(b.lo.x) + ext.lo.x)), int(clamp_extent(std::int64_t(b.lo.y) + ext.lo.y)),
           int(clamp_extent(std::int64_t(b.lo.z) + ext.lo.z))},
          {int(clamp_extent(std::int64_t(b.hi.x) + ext.hi.x - 1)), int(clamp_extent(std::int64_t(b.hi.y) + ext.hi.y - 1)),
           int(clamp_extent(std::int64_t(b.hi.z) + ext.hi.z - 1))}};
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

// One pass of the squared-distance transform along `axis`: each line's values become the
// lower envelope of parabolas w (p - q)^2 over them; with `seeds` the values are 0 or
// infinity (the first pass), which is cheaper. Values above `limit` become infinity.
// Instantiated for float and double (morphology_distance.cpp).
template <typename T>
void distance_pass(DenseGrid<T>& g, Axis axis, double w, double limit, bool seeds);
extern template void distance_pass<float>(DenseGrid<float>&, Axis, double, double, bool);
extern template void distance_pass<double>(DenseGrid<double>&, Axis, double, double, bool);

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

// ---- axial bodies (morphology_axial.cpp)

// The radius squared (in voxels^2) of an axial body at each level t along its axis.
struct AxialLevels {
  std::vector<double> radius_sq;  // levels 0..n-1; negative: empty level
  int tail_from = -1;             // an infinite tail from this level on, or -1
  double tail_radius_sq = -1;
};

AxialLevels axial_levels(const AxialBody& body, double h);
double widest_radius_sq(const AxialLevels& levels);
// Squared distances across `axis` (in the planes it is normal to) to the solid, up to
// `widest`: what every axial body along that axis needs, so bodies share it.
DenseGrid<float> distance_across(const Solid& solid, Axis axis, const IndexBox& work, double widest);
// The dilation by an axial body from the distances across its axis.
Solid sweep_axial(const DenseGrid<float>& perp, const AxialBody& body, const Lattice& lattice, const IndexBox& domain);
Solid dilate_axial(const Solid& solid, const AxialBody& body, const IndexBox& work, const IndexBox& domain);

// ---- offset sets (morphology_shifts.cpp, morphology_fft.cpp)

// The definition: every voxel plus every offset.
Solid dilate_brute_force(const Solid& solid, const std::vector<Index3>& offsets, const IndexBox& domain);
// The union of shifted copies, 64 voxels a word.
Solid dilate_shifts(const Solid& solid, const std::vector<Index3>& offsets, const IndexBox& source, const IndexBox& domain);
// The convolution of the solid's and the offsets' indicator functions, thresholded.
Solid dilate_fft(const Solid& solid, const std::vector<Index3>& offsets, const IndexBox& source, const IndexBox& domain);

}  // namespace hybridctl::geometry::detail
