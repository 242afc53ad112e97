// Separable squared-distance transforms: one pass per axis, each line the lower envelope
// of parabolas (Felzenszwalb & Huttenlocher, "Distance Transforms of Sampled Functions").

#include <cmath>

#include "geometry/morphology_internal.hpp"

namespace hybridctl::geometry::detail {

namespace {

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

}  // namespace

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

template void distance_pass<float>(DenseGrid<float>&, Axis, double, double, bool);
template void distance_pass<double>(DenseGrid<double>&, Axis, double, double, bool);

}  // namespace hybridctl::geometry::detail
