#pragma once
// Two-dimensional voxel slices for the toolpath generators: one z layer of a Solid as a
// byte mask over an XY window of voxel indices, with the few planar operations the
// generators need (disc growth and shrinking by exact Euclidean distance, boundary cells,
// row runs, boundary chains). Cells are addressed by absolute voxel indices (x, y) of the
// solid's lattice; everything outside the window reads as empty.

#include <cstdint>
#include <vector>

#include "geometry/solid.hpp"

namespace hybridctl::toolpaths {

struct Cell {
  int x = 0, y = 0;
  friend bool operator==(const Cell&, const Cell&) = default;
};

class SliceMask {
 public:
  SliceMask() = default;
  // An empty mask over cells [x0, x0 + nx) x [y0, y0 + ny).
  SliceMask(int x0, int y0, int nx, int ny);

  int x0() const { return x0_; }
  int y0() const { return y0_; }
  int nx() const { return nx_; }
  int ny() const { return ny_; }
  bool inside_window(int x, int y) const { return x >= x0_ && x < x0_ + nx_ && y >= y0_ && y < y0_ + ny_; }

  bool at(int x, int y) const { return inside_window(x, y) && cells_[index(x, y)] != 0; }
  bool at(Cell c) const { return at(c.x, c.y); }
  // Cells outside the window are ignored.
  void set(int x, int y, bool on = true) {
    if (inside_window(x, y)) cells_[index(x, y)] = on ? 1 : 0;
  }

  std::int64_t count() const;
  bool empty() const { return count() == 0; }

  // Cell-wise operations; both masks must share the window.
  SliceMask& operator&=(const SliceMask& other);
  SliceMask& operator|=(const SliceMask& other);
  SliceMask without(const SliceMask& other) const;

  const std::vector<std::uint8_t>& raw() const { return cells_; }

 private:
  std::size_t index(int x, int y) const { return std::size_t(y - y0_) * std::size_t(nx_) + std::size_t(x - x0_); }
  int x0_ = 0, y0_ = 0, nx_ = 0, ny_ = 0;
  std::vector<std::uint8_t> cells_;
};

// Layer z of `solid` over the XY window of `window` (its z range is ignored).
SliceMask slice_of(const geometry::Solid& solid, int z, const geometry::IndexBox& window);

// Squared Euclidean distance, in voxels^2, from every cell of the window to the nearest
// set cell of `mask` (exact, Felzenszwalb-Huttenlocher); a large value when none.
std::vector<double> squared_distance_to(const SliceMask& mask);

// The cells within `radius` voxels (centre to centre, closed) of a set cell.
SliceMask grow_by_disc(const SliceMask& mask, double radius_voxels);
// The cells whose whole closed disc of `radius` voxels lies in the mask (cells outside
// the window count as empty).
SliceMask shrink_by_disc(const SliceMask& mask, double radius_voxels);

// Set cells with a 4-neighbour that is not set (cells on the window's edge included).
SliceMask boundary_cells(const SliceMask& mask);

// A horizontal run of set cells [x_begin, x_end) in row y.
struct Run {
  int y = 0, x_begin = 0, x_end = 0;
};
std::vector<Run> row_runs(const SliceMask& mask, int y);
// The same for a column x, as runs [y_begin, y_end) stored in x_begin/x_end with y = x.
std::vector<Run> column_runs(const SliceMask& mask, int x);

// Orders the set cells of `cells` (typically boundary_cells) into chains of 8-neighbours,
// walking forwards and backwards from each unvisited cell; 4-neighbours are preferred.
// A chain whose ends are neighbours is closed: its first cell is repeated at its end.
std::vector<std::vector<Cell>> trace_chains(const SliceMask& cells);

// The tight box of the set cells; an empty vector when none ({x0, y0, x1, y1} half-open).
struct CellBox {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  bool empty() const { return x1 <= x0 || y1 <= y0; }
};
CellBox cell_bounds(const SliceMask& mask);

}  // namespace hybridctl::toolpaths

namespace hybridctl::toolpaths {

// For every cell of the XY window of `window`, the highest z index of a voxel of `solid`
// in that column, or kNoVoxel.
inline constexpr int kNoVoxel = -(1 << 30);
std::vector<int> column_top_indices(const geometry::Solid& solid, const geometry::IndexBox& window);

}  // namespace hybridctl::toolpaths
