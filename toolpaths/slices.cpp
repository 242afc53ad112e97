#include "toolpaths/slices.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace hybridctl::toolpaths {
namespace {

constexpr double kFar = 1e30;

// One-dimensional squared distance transform of sampled function f (Felzenszwalb and
// Huttenlocher, "Distance Transforms of Sampled Functions", 2012): d[q] = min_p f[p] + (q-p)^2.
void distance_1d(const double* f, double* d, int n, std::vector<int>& v, std::vector<double>& z) {
  v.assign(std::size_t(n), 0);
  z.assign(std::size_t(n) + 1, 0);
  int k = -1;
  for (int q = 0; q < n; ++q) {
    if (f[q] >= kFar) continue;
    if (k < 0) {
      k = 0;
      v[0] = q;
      z[0] = -kFar;
      z[1] = kFar;
      continue;
    }
    double s;
    while (true) {
      const int p = v[std::size_t(k)];
      s = ((f[q] + double(q) * q) - (f[p] + double(p) * p)) / (2.0 * (q - p));
      if (s <= z[std::size_t(k)] && k > 0) {
        --k;
        continue;
      }
      break;
    }
    if (s <= z[std::size_t(k)]) {  // k == 0 and the new parabola wins everywhere
      v[0] = q;
      z[0] = -kFar;
      z[1] = kFar;
      continue;
    }
    ++k;
    v[std::size_t(k)] = q;
    z[std::size_t(k)] = s;
    z[std::size_t(k) + 1] = kFar;
  }
  if (k < 0) {
    for (int q = 0; q < n; ++q) d[q] = kFar;
    return;
  }
  int j = 0;
  for (int q = 0; q < n; ++q) {
    while (z[std::size_t(j) + 1] < q) ++j;
    const int p = v[std::size_t(j)];
    d[q] = f[p] + double(q - p) * (q - p);
  }
}

}  // namespace

SliceMask::SliceMask(int x0, int y0, int nx, int ny)
    : x0_(x0), y0_(y0), nx_(std::max(nx, 0)), ny_(std::max(ny, 0)),
      cells_(std::size_t(std::max(nx, 0)) * std::size_t(std::max(ny, 0)), 0) {}

std::int64_t SliceMask::count() const {
  std::int64_t n = 0;
  for (auto c : cells_) n += c;
  return n;
}

SliceMask& SliceMask::operator&=(const SliceMask& other) {
  if (other.x0_ != x0_ || other.y0_ != y0_ || other.nx_ != nx_ || other.ny_ != ny_)
    throw std::invalid_argument("slice masks on different windows");
  for (std::size_t i = 0; i < cells_.size(); ++i) cells_[i] &= other.cells_[i];
  return *this;
}

SliceMask& SliceMask::operator|=(const SliceMask& other) {
  if (other.x0_ != x0_ || other.y0_ != y0_ || other.nx_ != nx_ || other.ny_ != ny_)
    throw std::invalid_argument("slice masks on different windows");
  for (std::size_t i = 0; i < cells_.size(); ++i) cells_[i] |= other.cells_[i];
  return *this;
}

SliceMask SliceMask::without(const SliceMask& other) const {
  if (other.x0_ != x0_ || other.y0_ != y0_ || other.nx_ != nx_ || other.ny_ != ny_)
    throw std::invalid_argument("slice masks on different windows");
  SliceMask r = *this;
  for (std::size_t i = 0; i < cells_.size(); ++i) r.cells_[i] = cells_[i] && !other.cells_[i];
  return r;
}

SliceMask slice_of(const geometry::Solid& solid, int z, const geometry::IndexBox& window) {
  SliceMask m(window.lo.x, window.lo.y, window.hi.x - window.lo.x, window.hi.y - window.lo.y);
  const geometry::IndexBox storage = solid.storage_box();
  if (storage.empty() || z < storage.lo.z || z >= storage.hi.z) return m;
  const int y0 = std::max(window.lo.y, storage.lo.y), y1 = std::min(window.hi.y, storage.hi.y);
  const int xa = std::max(window.lo.x, storage.lo.x), xb = std::min(window.hi.x, storage.hi.x);
  if (xa >= xb) return m;
  for (int y = y0; y < y1; ++y) {
    const auto row = solid.row(y, z);
    const int first = solid.first_word();
    for (int w = (xa >> 6); w <= ((xb - 1) >> 6); ++w) {
      std::uint64_t bits = row[std::size_t(w - first)];
      while (bits) {
        const int b = std::countr_zero(bits);
        bits &= bits - 1;
        const int x = w * 64 + b;
        if (x >= xa && x < xb) m.set(x, y);
      }
    }
  }
  return m;
}

std::vector<double> squared_distance_to(const SliceMask& mask) {
  const int nx = mask.nx(), ny = mask.ny();
  std::vector<double> g(std::size_t(nx) * std::size_t(ny));
  for (std::size_t i = 0; i < g.size(); ++i) g[i] = mask.raw()[i] ? 0.0 : kFar;
  std::vector<int> v;
  std::vector<double> z, f(std::size_t(std::max(nx, ny))), d(std::size_t(std::max(nx, ny)));
  for (int y = 0; y < ny; ++y) {  // rows
    double* row = g.data() + std::size_t(y) * std::size_t(nx);
    std::copy(row, row + nx, f.begin());
    distance_1d(f.data(), row, nx, v, z);
  }
  for (int x = 0; x < nx; ++x) {  // columns
    for (int y = 0; y < ny; ++y) f[std::size_t(y)] = g[std::size_t(y) * std::size_t(nx) + std::size_t(x)];
    distance_1d(f.data(), d.data(), ny, v, z);
    for (int y = 0; y < ny; ++y) g[std::size_t(y) * std::size_t(nx) + std::size_t(x)] = d[std::size_t(y)];
  }
  return g;
}

SliceMask grow_by_disc(const SliceMask& mask, double radius_voxels) {
  const std::vector<double> d = squared_distance_to(mask);
  SliceMask r(mask.x0(), mask.y0(), mask.nx(), mask.ny());
  const double r2 = radius_voxels * radius_voxels + 1e-9;
  for (int y = 0; y < mask.ny(); ++y)
    for (int x = 0; x < mask.nx(); ++x)
      if (d[std::size_t(y) * std::size_t(mask.nx()) + std::size_t(x)] <= r2) r.set(mask.x0() + x, mask.y0() + y);
  return r;
}

SliceMask shrink_by_disc(const SliceMask& mask, double radius_voxels) {
  // The complement includes everything outside the window: pad the window by the radius.
  const int pad = int(std::ceil(radius_voxels)) + 1;
  SliceMask outside(mask.x0() - pad, mask.y0() - pad, mask.nx() + 2 * pad, mask.ny() + 2 * pad);
  for (int y = outside.y0(); y < outside.y0() + outside.ny(); ++y)
    for (int x = outside.x0(); x < outside.x0() + outside.nx(); ++x)
      if (!mask.at(x, y)) outside.set(x, y);
  const std::vector<double> d = squared_distance_to(outside);
  SliceMask r(mask.x0(), mask.y0(), mask.nx(), mask.ny());
  const double r2 = radius_voxels * radius_voxels + 1e-9;
  for (int y = mask.y0(); y < mask.y0() + mask.ny(); ++y)
    for (int x = mask.x0(); x < mask.x0() + mask.nx(); ++x) {
      const double v = d[std::size_t(y - outside.y0()) * std::size_t(outside.nx()) + std::size_t(x - outside.x0())];
      if (mask.at(x, y) && v > r2) r.set(x, y);
    }
  return r;
}

SliceMask boundary_cells(const SliceMask& mask) {
  SliceMask r(mask.x0(), mask.y0(), mask.nx(), mask.ny());
  for (int y = mask.y0(); y < mask.y0() + mask.ny(); ++y)
    for (int x = mask.x0(); x < mask.x0() + mask.nx(); ++x)
      if (mask.at(x, y) && (!mask.at(x - 1, y) || !mask.at(x + 1, y) || !mask.at(x, y - 1) || !mask.at(x, y + 1)))
        r.set(x, y);
  return r;
}

std::vector<Run> row_runs(const SliceMask& mask, int y) {
  std::vector<Run> runs;
  const int x1 = mask.x0() + mask.nx();
  for (int x = mask.x0(); x < x1;) {
    if (!mask.at(x, y)) {
      ++x;
      continue;
    }
    int e = x;
    while (e < x1 && mask.at(e, y)) ++e;
    runs.push_back({y, x, e});
    x = e;
  }
  return runs;
}

std::vector<Run> column_runs(const SliceMask& mask, int x) {
  std::vector<Run> runs;
  const int y1 = mask.y0() + mask.ny();
  for (int y = mask.y0(); y < y1;) {
    if (!mask.at(x, y)) {
      ++y;
      continue;
    }
    int e = y;
    while (e < y1 && mask.at(x, e)) ++e;
    runs.push_back({x, y, e});
    y = e;
  }
  return runs;
}

std::vector<std::vector<Cell>> trace_chains(const SliceMask& cells) {
  static constexpr int kSteps[8][2] = {{1, 0}, {0, 1}, {-1, 0}, {0, -1}, {1, 1}, {-1, 1}, {-1, -1}, {1, -1}};
  SliceMask left = cells;
  std::vector<std::vector<Cell>> chains;
  auto next_from = [&](Cell c, Cell& out) {
    // Prefer the neighbour with the fewest onward choices: it keeps thin spurs from
    // being stranded as separate chains.
    int best = -1, best_degree = 0;
    for (int i = 0; i < 8; ++i) {
      const Cell n{c.x + kSteps[i][0], c.y + kSteps[i][1]};
      if (!left.at(n)) continue;
      int degree = 0;
      for (const auto& s : kSteps) degree += left.at(n.x + s[0], n.y + s[1]) ? 1 : 0;
      // 4-neighbours win over diagonals at equal degree.
      const int key = degree * 2 + (i >= 4 ? 1 : 0);
      if (best < 0 || key < best_degree) {
        best = i;
        best_degree = key;
      }
    }
    if (best < 0) return false;
    out = {c.x + kSteps[best][0], c.y + kSteps[best][1]};
    return true;
  };
  for (int y = cells.y0(); y < cells.y0() + cells.ny(); ++y)
    for (int x = cells.x0(); x < cells.x0() + cells.nx(); ++x) {
      if (!left.at(x, y)) continue;
      std::vector<Cell> forward{{x, y}};
      left.set(x, y, false);
      Cell c{x, y}, n;
      while (next_from(c, n)) {
        left.set(n.x, n.y, false);
        forward.push_back(n);
        c = n;
      }
      std::vector<Cell> backward;
      c = {x, y};
      while (next_from(c, n)) {
        left.set(n.x, n.y, false);
        backward.push_back(n);
        c = n;
      }
      std::vector<Cell> chain(backward.rbegin(), backward.rend());
      chain.insert(chain.end(), forward.begin(), forward.end());
      if (chain.size() > 2) {
        const Cell a = chain.front(), b = chain.back();
        if (std::abs(a.x - b.x) <= 1 && std::abs(a.y - b.y) <= 1) chain.push_back(a);
      }
      chains.push_back(std::move(chain));
    }
  return chains;
}

CellBox cell_bounds(const SliceMask& mask) {
  CellBox b{std::numeric_limits<int>::max(), std::numeric_limits<int>::max(), std::numeric_limits<int>::min(),
            std::numeric_limits<int>::min()};
  bool any = false;
  for (int y = mask.y0(); y < mask.y0() + mask.ny(); ++y)
    for (int x = mask.x0(); x < mask.x0() + mask.nx(); ++x)
      if (mask.at(x, y)) {
        any = true;
        b.x0 = std::min(b.x0, x);
        b.y0 = std::min(b.y0, y);
        b.x1 = std::max(b.x1, x + 1);
        b.y1 = std::max(b.y1, y + 1);
      }
  return any ? b : CellBox{};
}

}  // namespace hybridctl::toolpaths

namespace hybridctl::toolpaths {

std::vector<int> column_top_indices(const geometry::Solid& solid, const geometry::IndexBox& window) {
  const int nx = window.hi.x - window.lo.x, ny = window.hi.y - window.lo.y;
  std::vector<int> top(std::size_t(std::max(nx, 0)) * std::size_t(std::max(ny, 0)), kNoVoxel);
  const geometry::IndexBox bb = solid.bounding_box();
  if (bb.empty() || nx <= 0 || ny <= 0) return top;
  const int y0 = std::max(window.lo.y, bb.lo.y), y1 = std::min(window.hi.y, bb.hi.y);
  const int xa = std::max(window.lo.x, bb.lo.x), xb = std::min(window.hi.x, bb.hi.x);
  if (xa >= xb) return top;
  const int first = solid.first_word();
  for (int z = bb.lo.z; z < bb.hi.z; ++z)
    for (int y = y0; y < y1; ++y) {
      const auto row = solid.row(y, z);
      for (int w = (xa >> 6); w <= ((xb - 1) >> 6); ++w) {
        std::uint64_t bits = row[std::size_t(w - first)];
        while (bits) {
          const int x = w * 64 + std::countr_zero(bits);
          bits &= bits - 1;
          if (x >= xa && x < xb) top[std::size_t(y - window.lo.y) * std::size_t(nx) + std::size_t(x - window.lo.x)] = z;
        }
      }
    }
  return top;
}

}  // namespace hybridctl::toolpaths
