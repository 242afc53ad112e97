#include "planner/atoms/deposit_reach.hpp"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdint>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "geometry/sliding_extremum.hpp"

namespace hybridctl::planner {

namespace {

// A domain seen along a build axis: columns (u, v) across it, t along it towards the head.
struct ColumnFrame {
  int axis, ua, va, sign;
  int lo[3], hi[3];
  ColumnFrame(const geometry::IndexBox& d, geometry::AxisDirection approach)
      : axis(approach.axis == geometry::Axis::X ? 0 : approach.axis == geometry::Axis::Y ? 1 : 2),
        ua((axis + 1) % 3),
        va((axis + 2) % 3),
        sign(approach.sign),
        lo{d.lo.x, d.lo.y, d.lo.z},
        hi{d.hi.x, d.hi.y, d.hi.z} {}
  int nu() const { return hi[ua] - lo[ua]; }
  int nv() const { return hi[va] - lo[va]; }
  int length() const { return hi[axis] - lo[axis]; }
  int atom(const AtomDecomposition& atoms, int u, int v, int t) const {
    int c[3];
    c[ua] = lo[ua] + u, c[va] = lo[va] + v;
    c[axis] = sign > 0 ? lo[axis] + t : hi[axis] - 1 - t;
    return atoms.atom_at_unchecked(c[0] - lo[0], c[1], c[2]);
  }
};

// out[o] (o in [0, n_out), position out_first + o) = the largest in[i] (position
// in_first + i, i in [0, n_in)) within `half` positions, -1 when none: the sliding
// maximum of van Herk and Gil-Werman (geometry/sliding_extremum.hpp).
void window_max(const int* in, int in_stride, int in_first, int n_in, int half, int out_first, int n_out, int* out,
                int out_stride, std::vector<int>& scratch) {
  const int w = 2 * half + 1;
  // p[k] = the input at position out_first - half + k, -1 beyond it; out[o] = max p[o .. o + w).
  const int len = n_out + w - 1;
  const int blocks = (len + w - 1) / w;
  scratch.assign(std::size_t(3) * std::size_t(blocks) * std::size_t(w), -1);
  int* p = scratch.data();
  int* g = p + std::size_t(blocks) * std::size_t(w);  // max from the block's start
  int* h = g + std::size_t(blocks) * std::size_t(w);  // max to the block's end
  for (int i = 0; i < n_in; ++i) {
    const int k = in_first + i - (out_first - half);
    if (k >= 0 && k < len) p[k] = in[std::size_t(i) * std::size_t(in_stride)];
  }
  const auto larger = [](int a, int b) { return std::max(a, b); };
  geometry::block_extrema(p, blocks * w, w, g, h, larger);
  for (int o = 0; o < n_out; ++o)
    out[std::size_t(o) * std::size_t(out_stride)] = geometry::window_extremum(g, h, o, w, larger);
}

}  // namespace

std::vector<AtomSet> atoms_above(const AtomDecomposition& atoms, geometry::AxisDirection approach, int gap) {
  const int n = atoms.atom_count();
  std::vector<AtomSet> above(static_cast<std::size_t>(n));
  const geometry::IndexBox& d = atoms.domain();
  if (d.empty()) return above;
  const ColumnFrame f(d, approach);
  const int len = f.length();
  struct Run {
    int atom, first, last;  // positions along the column, from the far side
  };
  std::vector<Run> runs;
  for (int v = 0; v < f.nv(); ++v)
    for (int u = 0; u < f.nu(); ++u) {
      runs.clear();
      for (int t = 0; t < len; ++t) {
        const int a = f.atom(atoms, u, v, t);
        if (!runs.empty() && runs.back().atom == a)
          runs.back().last = t;
        else
          runs.push_back({a, t, t});
      }
      // Run j lies above run i; some voxel of j is `gap` above some voxel of i when j's
      // last reaches i's first plus the gap.
      for (std::size_t i = 0; i < runs.size(); ++i)
        for (std::size_t j = i + 1; j < runs.size(); ++j) {
          if (runs[j].atom == runs[i].atom || runs[j].last < runs[i].first + gap) continue;
          AtomSet& s = above[std::size_t(runs[i].atom)];
          if (s.words().empty()) s = AtomSet(n);
          s.set(runs[j].atom);
        }
    }
  return above;
}


std::vector<AtomSet> atoms_in_nozzle_reach(const AtomDecomposition& atoms, geometry::AxisDirection approach,
                                           const NozzleReach& nozzle) {
  const int n = atoms.atom_count();
  std::vector<AtomSet> reach(static_cast<std::size_t>(n));
  if (atoms.domain().empty() || nozzle.radius <= 0) return reach;
  const ColumnFrame f(atoms.domain(), approach);
  const int nu = f.nu(), nv = f.nv(), len = f.length();
  // Per column the atoms in it with their lowest and highest voxel along the build axis,
  // and per atom its columns' box.
  constexpr int kNone = -1;
  struct Entry {
    int atom, lowest, highest;
  };
  std::vector<std::vector<Entry>> in_column(std::size_t(nu) * std::size_t(nv));
  struct Box2 {
    int u0 = INT32_MAX, v0 = INT32_MAX, u1 = -1, v1 = -1;
  };
  std::vector<Box2> box(static_cast<std::size_t>(n));
  for (int v = 0; v < nv; ++v)
    for (int u = 0; u < nu; ++u) {
      auto& column = in_column[std::size_t(v) * std::size_t(nu) + std::size_t(u)];
      for (int t = 0; t < len; ++t) {
        const int a = f.atom(atoms, u, v, t);
        if (!column.empty() && column.back().atom == a) {  // most voxels continue a run
          column.back().highest = t;
          continue;
        }
        const auto e = std::find_if(column.begin(), column.end(), [a](const Entry& x) { return x.atom == a; });
        if (e != column.end()) {
          e->highest = t;
          continue;
        }
        column.push_back({a, t, t});
        Box2& b = box[std::size_t(a)];
        b.u0 = std::min(b.u0, u), b.v0 = std::min(b.v0, v), b.u1 = std::max(b.u1, u), b.v1 = std::max(b.v1, v);
      }
    }
  // Half the side of the square inscribed in the body's circle, in whole voxels.
  const int half = int(std::floor(nozzle.radius / std::sqrt(2.0) + 1e-9));
  // The atoms are independent: in parallel, each thread with its own relation (merged
  // after) and scratch.
  struct Local {
    std::vector<AtomSet> reach;
    std::vector<int> highest, row, top, scratch;
  };
  tbb::enumerable_thread_specific<Local> locals([n] { return Local{std::vector<AtomSet>(std::size_t(n)), {}, {}, {}, {}}; });
  tbb::parallel_for(tbb::blocked_range<int>(0, n, 16), [&](const tbb::blocked_range<int>& range) {
    Local& l = locals.local();
    for (int a = range.begin(); a != range.end(); ++a) {
      const Box2& b = box[std::size_t(a)];
      if (b.u1 < 0) continue;
      // The highest voxel of `a` within the square around each column (a separable max).
      const int u0 = std::max(0, b.u0 - half), u1 = std::min(nu - 1, b.u1 + half);
      const int v0 = std::max(0, b.v0 - half), v1 = std::min(nv - 1, b.v1 + half);
      const int wu = u1 - u0 + 1, wv = v1 - v0 + 1;
      const int bu = b.u1 - b.u0 + 1;
      l.highest.assign(std::size_t(bu) * std::size_t(b.v1 - b.v0 + 1), kNone);
      for (int v = b.v0; v <= b.v1; ++v)
        for (int u = b.u0; u <= b.u1; ++u)
          for (const Entry& e : in_column[std::size_t(v) * std::size_t(nu) + std::size_t(u)])
            if (e.atom == a) l.highest[std::size_t(v - b.v0) * std::size_t(bu) + std::size_t(u - b.u0)] = e.highest;
      l.row.assign(std::size_t(wu) * std::size_t(wv), kNone);
      for (int v = b.v0; v <= b.v1; ++v)
        window_max(&l.highest[std::size_t(v - b.v0) * std::size_t(bu)], 1, b.u0, bu, half, u0, wu,
                   &l.row[std::size_t(v - v0) * std::size_t(wu)], 1, l.scratch);
      l.top.assign(l.row.size(), kNone);
      const int bv = b.v1 - b.v0 + 1;
      for (int u = u0; u <= u1; ++u)
        window_max(&l.row[std::size_t(b.v0 - v0) * std::size_t(wu) + std::size_t(u - u0)], wu, b.v0, bv, half, v0, wv,
                   &l.top[std::size_t(u - u0)], wu, l.scratch);
      // Every atom with a voxel the body over it would reach `a` from.
      for (int v = v0; v <= v1; ++v)
        for (int u = u0; u <= u1; ++u) {
          const int t = l.top[std::size_t(v - v0) * std::size_t(wu) + std::size_t(u - u0)];
          if (t == kNone) continue;
          for (const Entry& e : in_column[std::size_t(v) * std::size_t(nu) + std::size_t(u)]) {
            const int other = e.atom;
            // `a`'s highest voxel near the column lies in the body over some voxel of
            // `other` there: from the stand-off over its lowest to the body's top over its
            // highest. Higher than that, the body might pass under it: not counted.
            if (other == a || t < e.lowest + nozzle.standoff || t > e.highest + nozzle.standoff + nozzle.length) continue;
            AtomSet& s = l.reach[std::size_t(other)];
            if (s.words().empty()) s = AtomSet(n);
            s.set(a);
          }
        }
    }
  });
  for (const Local& l : locals)
    for (std::size_t o = 0; o < l.reach.size(); ++o) {
      const auto& from = l.reach[o].words();
      if (from.empty()) continue;
      AtomSet& into = reach[o];
      if (into.words().empty()) {
        into = l.reach[o];
        continue;
      }
      for (std::size_t w = 0; w < from.size(); ++w) into.words()[w] |= from[w];
    }
  return reach;
}

DepositFooting deposit_footing(const AtomDecomposition& atoms, const geometry::Solid& region,
                               geometry::AxisDirection approach, int reach) {
  const int n = atoms.atom_count();
  DepositFooting out;
  out.kind.assign(std::size_t(n), DepositFooting::None);
  std::vector<AtomSet> carriers_of(static_cast<std::size_t>(n));
  const geometry::IndexBox& d = atoms.domain();
  const geometry::IndexBox bb = geometry::box_intersection(region.bounding_box(), d);
  if (bb.empty()) {
    out.carriers = AtomRelation(std::move(carriers_of));
    return out;
  }
  const ColumnFrame f(d, approach);
  const int lo[3] = {bb.lo.x, bb.lo.y, bb.lo.z}, hi[3] = {bb.hi.x, bb.hi.y, bb.hi.z};
  // The first layer's position t along the column frame (0: the domain's lowest layer).
  const int first = f.sign > 0 ? lo[f.axis] - f.lo[f.axis] : f.hi[f.axis] - hi[f.axis];
  const int nu = f.nu(), nv = f.nv();
  auto in_region = [&](int u, int v) {
    int c[3];
    c[f.ua] = f.lo[f.ua] + u, c[f.va] = f.lo[f.va] + v;
    c[f.axis] = f.sign > 0 ? f.lo[f.axis] + first : f.hi[f.axis] - 1 - first;
    return region.contains({c[0], c[1], c[2]});
  };
  // Along each row of the first layer, cells of one atom in a run share their carriers'
  // rows: the window of the run is scanned once, not once per cell (a bead's reach is
  // tens of voxels).
  const int u_lo = lo[f.ua] - f.lo[f.ua], u_hi = hi[f.ua] - f.lo[f.ua];
  for (int v = lo[f.va] - f.lo[f.va]; v < hi[f.va] - f.lo[f.va]; ++v)
    for (int u = u_lo; u < u_hi;) {
      if (!in_region(u, v)) {
        ++u;
        continue;
      }
      const int b = f.atom(atoms, u, v, first);
      int end = u + 1;
      while (end < u_hi && in_region(end, v) && f.atom(atoms, end, v, first) == b) ++end;
      const int run_first = u;
      u = end;
      if (first == 0) {
        out.kind[std::size_t(b)] = DepositFooting::OnPlate;
        continue;
      }
      if (out.kind[std::size_t(b)] == DepositFooting::OnPlate) continue;
      if (out.kind[std::size_t(b)] == DepositFooting::None) {
        out.kind[std::size_t(b)] = DepositFooting::NeedsCarrier;
        carriers_of[std::size_t(b)] = AtomSet(n);
      }
      AtomSet& carriers = carriers_of[std::size_t(b)];
      const int w0 = std::max(0, run_first - reach), w1 = std::min(nu - 1, end - 1 + reach);
      for (int t = std::max(0, first - 2); t <= first; ++t)
        for (int dv = -reach; dv <= reach; ++dv) {
          if (v + dv < 0 || v + dv >= nv) continue;
          int last = -1;
          for (int wu = w0; wu <= w1; ++wu) {
            const int a = f.atom(atoms, wu, v + dv, t);
            if (a == last) continue;
            last = a;
            if (a != b) carriers.set(a);
          }
        }
    }
  out.carriers = AtomRelation(std::move(carriers_of));
  return out;
}

int deposit_reach_gap(double layer_height, double voxel_size) {
  // A layer holds at most floor(layer / h) + 1 voxel centres: material that many voxels
  // up lies in a later layer.
  return int(std::floor(layer_height / voxel_size + 1e-9)) + 1;
}

}  // namespace hybridctl::planner
