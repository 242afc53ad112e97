#pragma once
// The paths of one pocket level as cells (internal to toolpaths/pocket_*.cpp): voxel
// columns of the work frame joined by axis-aligned legs, the zigzag rows and boundary
// chains a level is cleared with, and the ways to start one of them.

#include <cstdlib>
#include <optional>
#include <vector>

#include "toolpaths/slices.hpp"

namespace hybridctl::toolpaths::pocket {

struct CellPath {
  std::vector<Cell> points;  // consecutive points share a row or a column
  bool closed = false;       // first == last
};

inline int manhattan(Cell a, Cell b) { return std::abs(a.x - b.x) + std::abs(a.y - b.y); }

inline Cell unit_towards(Cell a, Cell b) {
  return {b.x > a.x ? 1 : b.x < a.x ? -1 : 0, b.y > a.y ? 1 : b.y < a.y ? -1 : 0};
}

// Calls fn for every cell of the axis-aligned leg a -> b, a and b included.
template <class Fn>
void for_leg_cells(Cell a, Cell b, Fn fn) {
  const Cell d = unit_towards(a, b);
  Cell c = a;
  fn(c);
  while (!(c == b)) {
    c = {c.x + d.x, c.y + d.y};
    fn(c);
  }
}

// A link a -> b inside `usable`: straight, or two legs through a corner.
std::optional<std::vector<Cell>> link_cells(Cell a, Cell b, const SliceMask& usable);

// Rows along X (`along_x`) or Y every `spacing` cells from the region's first row, with
// its last row added, each cut into the region's runs.
std::vector<CellPath> zigzag_rows(const SliceMask& region, bool along_x, int spacing);

// Boundary chains (8-connected) as axis-aligned paths: a diagonal step goes round the
// corner cell that is usable (preferring one in `region`); with neither, the chain splits.
std::vector<CellPath> chain_paths(const SliceMask& cells, const SliceMask& region, const SliceMask& usable);

// A way to start one of the paths still to cut: from its front (mode 0), from its back
// (mode 1, the path runs backwards), or for a closed path from its waypoint `at` (mode 2).
struct Candidate {
  std::size_t path = 0;
  int mode = 0;
  std::size_t at = 0;
  int distance = 0;
};

// Every way to start a path, nearest to `from` first.
std::vector<Candidate> candidates(const std::vector<CellPath>& todo, Cell from);
// The path as the candidate starts it.
CellPath oriented(const CellPath& path, const Candidate& c);

}  // namespace hybridctl::toolpaths::pocket
