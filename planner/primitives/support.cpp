#include "planner/primitives/support.hpp"

#include <algorithm>

namespace hybridctl::planner {
namespace {

using geometry::Index3;
using geometry::IndexBox;
using instruments::LayerGrid;

// A layer's in-plane axes (u, v) and its build axis w, as lattice coordinates. The rule is
// symmetric in u and v (a round footprint, bridges along both), so their order is free.
struct LayerFrame {
  geometry::Axis axis;
  Index3 voxel(int u, int v, int w) const {
    switch (axis) {
      case geometry::Axis::X: return {w, u, v};
      case geometry::Axis::Y: return {v, w, u};
      case geometry::Axis::Z: break;
    }
    return {u, v, w};
  }
  // (u, v, w) ranges of a box.
  void ranges(const IndexBox& b, int lo[3], int hi[3]) const {
    const Index3 l = b.lo, h = b.hi;
    switch (axis) {
      case geometry::Axis::X: lo[0] = l.y, lo[1] = l.z, lo[2] = l.x, hi[0] = h.y, hi[1] = h.z, hi[2] = h.x; return;
      case geometry::Axis::Y: lo[0] = l.z, lo[1] = l.x, lo[2] = l.y, hi[0] = h.z, hi[1] = h.x, hi[2] = h.y; return;
      case geometry::Axis::Z: break;
    }
    lo[0] = l.x, lo[1] = l.y, lo[2] = l.z, hi[0] = h.x, hi[1] = h.y, hi[2] = h.z;
  }
};

}  // namespace

geometry::Solid self_supporting(const geometry::Solid& region, geometry::AxisDirection build,
                                const instruments::SupportRule& rule, const geometry::Solid* present) {
  geometry::Solid out(region.lattice(), region.storage_box());
  const IndexBox bb = region.bounding_box();
  if (bb.empty()) return out;
  const LayerFrame frame{build.axis};
  int lo[3], hi[3];
  frame.ranges(bb, lo, hi);
  const int nu = hi[0] - lo[0], nv = hi[1] - lo[1], layers = hi[2] - lo[2];
  const LayerGrid empty(lo[0], lo[1], nu, nv);
  // The layers built so far, held and bridged, from the first (on the plate).
  std::vector<LayerGrid> held, bridged, present_cells;
  std::vector<instruments::Below> below;
  for (int i = 0; i < layers; ++i) {
    const int w = build.sign > 0 ? lo[2] + i : hi[2] - 1 - i;
    LayerGrid candidates = empty;
    for (int v = lo[1]; v < hi[1]; ++v)
      for (int u = lo[0]; u < hi[0]; ++u)
        if (region.contains(frame.voxel(u, v, w))) candidates.set(u, v);
    // What each look-back finds: the layer n below, and the bridges laid since (footings).
    below.clear();
    for (const int n : instruments::look_backs(i)) {
      instruments::Below target{n, held[std::size_t(i - n)]};
      for (int j = i - n + 1; rule.max_bridge_voxels > 0 && j < i; ++j)
        for (std::size_t c = 0; c < target.material.cells.size(); ++c)
          target.material.cells[c] |= bridged[std::size_t(j)].cells[c];
      // Material there before the build is a foundation: what it holds in the layers since
      // counts for every look-back, as the layer under a deposit is all a bead needs.
      for (int j = i - n + 1; present && j < i; ++j)
        for (std::size_t c = 0; c < target.material.cells.size(); ++c)
          target.material.cells[c] |= present_cells[std::size_t(j)].cells[c];
      below.push_back(std::move(target));
    }
    instruments::HeldCells layer = instruments::supported_cells(candidates, below, empty, rule);
    if (present) {
      LayerGrid there = empty;
      for (int v = lo[1]; v < hi[1]; ++v)
        for (int u = lo[0]; u < hi[0]; ++u)
          if (present->contains(frame.voxel(u, v, w))) layer.held.set(u, v), there.set(u, v);
      present_cells.push_back(std::move(there));
    }
    for (int v = lo[1]; v < hi[1]; ++v)
      for (int u = lo[0]; u < hi[0]; ++u)
        if (layer.held.filled(u, v) && candidates.filled(u, v)) out.set(frame.voxel(u, v, w));
    held.push_back(std::move(layer.held));
    bridged.push_back(std::move(layer.bridged));
  }
  return out;
}

}  // namespace hybridctl::planner
