#include "instruments/support_rule.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <utility>

namespace hybridctl::instruments {

SupportRule support_rule(const config::SupportLimits& limits, double voxel_size) {
  if (!(voxel_size > 0)) throw std::invalid_argument("support_rule: the voxel size must be > 0");
  SupportRule rule;
  rule.lean_per_layer = std::tan(limits.max_overhang * std::numbers::pi / 180.0);
  rule.max_bridge_voxels = int(std::floor(limits.max_bridge / voxel_size + 1e-9));
  return rule;
}

namespace {

constexpr double kFar = std::numeric_limits<double>::infinity();

// Squared distance along one line to the nearest cell with f = 0 (Felzenszwalb and
// Huttenlocher's lower envelope of parabolas); f holds 0 or kFar, or earlier passes.
void envelope_1d(std::vector<double>& f, std::vector<double>& d, std::vector<int>& v, std::vector<double>& z) {
  const int n = int(f.size());
  int k = -1;
  for (int q = 0; q < n; ++q) {
    if (f[q] == kFar) continue;
    while (k >= 0) {
      const double s = ((f[q] + double(q) * q) - (f[v[k]] + double(v[k]) * v[k])) / (2.0 * (q - v[k]));
      if (s > z[k]) break;
      --k;
    }
    ++k;
    v[k] = q;
    z[k] = k == 0 ? -kFar : ((f[q] + double(q) * q) - (f[v[k - 1]] + double(v[k - 1]) * v[k - 1])) / (2.0 * (q - v[k - 1]));
    z[k + 1] = kFar;
  }
  for (int q = 0, j = 0; q < n; ++q) {
    if (k < 0) {
      d[q] = kFar;
      continue;
    }
    while (z[j + 1] < q) ++j;
    d[q] = double(q - v[j]) * (q - v[j]) + f[v[j]];
  }
}

// Squared Euclidean distance (voxels²) from every cell to the nearest filled cell of g.
std::vector<double> squared_distances(const LayerGrid& g) {
  std::vector<double> out(g.cells.size());
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = g.cells[i] ? 0.0 : kFar;
  const std::size_t longest = std::size_t(std::max(g.nx, g.ny));
  std::vector<double> f(longest), d(longest), z(longest + 1);
  std::vector<int> v(longest);
  auto pass = [&](int lines, int length, auto at) {
    f.resize(std::size_t(length));
    d.resize(std::size_t(length));
    for (int line = 0; line < lines; ++line) {
      for (int i = 0; i < length; ++i) f[std::size_t(i)] = out[at(line, i)];
      envelope_1d(f, d, v, z);
      for (int i = 0; i < length; ++i) out[at(line, i)] = d[std::size_t(i)];
    }
  };
  pass(g.ny, g.nx, [&](int y, int x) { return std::size_t(y) * std::size_t(g.nx) + std::size_t(x); });
  pass(g.nx, g.ny, [&](int x, int y) { return std::size_t(y) * std::size_t(g.nx) + std::size_t(x); });
  return out;
}

// Candidate cells not yet held, in runs along one axis held at both ends by `held` cells
// and at most `max_run` long, become held (and bridged).
void bridge_runs(const LayerGrid& candidates, LayerGrid& held, LayerGrid& bridged, int max_run, bool along_x) {
  const int lines = along_x ? candidates.ny : candidates.nx, length = along_x ? candidates.nx : candidates.ny;
  auto cell = [&](int line, int i) {
    return along_x ? std::pair{candidates.x0 + i, candidates.y0 + line} : std::pair{candidates.x0 + line, candidates.y0 + i};
  };
  auto open = [&](int line, int i) {
    const auto [x, y] = cell(line, i);
    return candidates.filled(x, y) && !held.filled(x, y);
  };
  auto holds = [&](int line, int i) {
    if (i < 0 || i >= length) return false;
    const auto [x, y] = cell(line, i);
    return held.filled(x, y);
  };
  for (int line = 0; line < lines; ++line)
    for (int i = 0; i < length;) {
      if (!open(line, i)) {
        ++i;
        continue;
      }
      int end = i;  // [i, end): a run of candidates not yet held
      while (end < length && open(line, end)) ++end;
      if (holds(line, i - 1) && holds(line, end) && end - i <= max_run)
        for (int k = i; k < end; ++k) {
          const auto [x, y] = cell(line, k);
          held.set(x, y);
          bridged.set(x, y);
        }
      i = end;
    }
}

}  // namespace

std::vector<int> look_backs(int built) {
  std::vector<int> out;
  for (const int n : SupportRule::kLookBack)
    if (n <= built) out.push_back(n);
  if (built > 0 && built < SupportRule::kLookBack.back() && (out.empty() || out.back() != built)) out.push_back(built);
  return out;
}

HeldCells supported_cells(const LayerGrid& candidates, std::span<const Below> below, const LayerGrid& present,
                          const SupportRule& rule) {
  HeldCells out{candidates, LayerGrid(candidates.x0, candidates.y0, candidates.nx, candidates.ny)};
  for (const Below& b : below) {
    const double reach = rule.reach(b.layers);
    const std::vector<double> d2 = squared_distances(b.material);
    for (std::size_t c = 0; c < out.held.cells.size(); ++c)
      if (out.held.cells[c] && d2[c] > reach * reach + 1e-9) out.held.cells[c] = 0;
  }
  if (rule.max_bridge_voxels <= 0) return out;
  // Bridges rest on held cells and on material already in the layer.
  LayerGrid anchors = out.held;
  for (std::size_t c = 0; c < anchors.cells.size(); ++c)
    if (present.cells.size() == anchors.cells.size() && present.cells[c]) anchors.cells[c] = 1;
  bridge_runs(candidates, anchors, out.bridged, rule.max_bridge_voxels, true);
  bridge_runs(candidates, anchors, out.bridged, rule.max_bridge_voxels, false);
  for (std::size_t c = 0; c < out.held.cells.size(); ++c) out.held.cells[c] = candidates.cells[c] && anchors.cells[c];
  return out;
}

}  // namespace hybridctl::instruments
