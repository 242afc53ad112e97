#include "toolpaths/pocket_cells.hpp"

#include <algorithm>

namespace hybridctl::toolpaths::pocket {
namespace {

bool leg_inside(Cell a, Cell b, const SliceMask& usable) {
  if (a.x != b.x && a.y != b.y) return false;
  bool ok = true;
  for_leg_cells(a, b, [&](Cell c) { ok = ok && usable.at(c); });
  return ok;
}

// Drops middle points of straight runs.
std::vector<Cell> simplify(const std::vector<Cell>& pts) {
  std::vector<Cell> out;
  for (const Cell& c : pts) {
    if (!out.empty() && out.back() == c) continue;
    if (out.size() >= 2) {
      const Cell a = out[out.size() - 2], b = out.back();
      if ((a.x == b.x && b.x == c.x) || (a.y == b.y && b.y == c.y)) {
        const Cell d1 = unit_towards(a, b), d2 = unit_towards(b, c);
        if (d1 == d2) out.pop_back();
      }
    }
    out.push_back(c);
  }
  return out;
}

}  // namespace

std::optional<std::vector<Cell>> link_cells(Cell a, Cell b, const SliceMask& usable) {
  if (a == b) return std::vector<Cell>{};
  if ((a.x == b.x || a.y == b.y) && leg_inside(a, b, usable)) return std::vector<Cell>{b};
  for (Cell corner : {Cell{b.x, a.y}, Cell{a.x, b.y}})
    if (leg_inside(a, corner, usable) && leg_inside(corner, b, usable)) return std::vector<Cell>{corner, b};
  return std::nullopt;
}

std::vector<CellPath> zigzag_rows(const SliceMask& region, bool along_x, int spacing) {
  std::vector<CellPath> out;
  const CellBox b = cell_bounds(region);
  if (b.empty()) return out;
  const int lo = along_x ? b.y0 : b.x0, hi = along_x ? b.y1 : b.x1;
  std::vector<int> rows;
  for (int v = lo; v < hi; v += spacing) rows.push_back(v);
  if (rows.back() != hi - 1) rows.push_back(hi - 1);
  for (int v : rows) {
    const std::vector<Run> runs = along_x ? row_runs(region, v) : column_runs(region, v);
    for (const Run& r : runs) {
      CellPath p;
      if (along_x) p.points = {{r.x_begin, v}, {r.x_end - 1, v}};
      else p.points = {{v, r.x_begin}, {v, r.x_end - 1}};
      if (p.points[0] == p.points[1]) p.points.pop_back();
      out.push_back(std::move(p));
    }
  }
  return out;
}

std::vector<CellPath> chain_paths(const SliceMask& cells, const SliceMask& region, const SliceMask& usable) {
  std::vector<CellPath> out;
  for (const auto& chain : trace_chains(cells)) {
    CellPath p;
    auto flush = [&]() {
      if (!p.points.empty()) {
        p.points = simplify(p.points);
        p.closed = p.points.size() > 2 && p.points.front() == p.points.back();
        out.push_back(std::move(p));
      }
      p = CellPath{};
    };
    for (std::size_t i = 0; i < chain.size(); ++i) {
      const Cell c = chain[i];
      if (!p.points.empty()) {
        const Cell a = p.points.back();
        if (a.x != c.x && a.y != c.y) {
          const Cell k1{c.x, a.y}, k2{a.x, c.y};
          const bool u1 = usable.at(k1), u2 = usable.at(k2);
          if (u1 && (region.at(k1) || !u2)) p.points.push_back(k1);
          else if (u2) p.points.push_back(k2);
          else flush();
        }
      }
      p.points.push_back(c);
    }
    flush();
  }
  return out;
}

std::vector<Candidate> candidates(const std::vector<CellPath>& todo, Cell from) {
  std::vector<Candidate> out;
  for (std::size_t i = 0; i < todo.size(); ++i) {
    const CellPath& p = todo[i];
    if (p.closed) {
      for (std::size_t j = 0; j + 1 < p.points.size(); ++j) out.push_back({i, 2, j, manhattan(from, p.points[j])});
    } else {
      out.push_back({i, 0, 0, manhattan(from, p.points.front())});
      if (p.points.size() > 1) out.push_back({i, 1, 0, manhattan(from, p.points.back())});
    }
  }
  std::stable_sort(out.begin(), out.end(), [](const Candidate& a, const Candidate& b) { return a.distance < b.distance; });
  return out;
}

CellPath oriented(const CellPath& path, const Candidate& c) {
  CellPath p = path;
  if (c.mode == 1) std::reverse(p.points.begin(), p.points.end());
  if (c.mode == 2 && c.at > 0) {
    std::vector<Cell> loop(p.points.begin(), p.points.end() - 1);
    std::rotate(loop.begin(), loop.begin() + std::ptrdiff_t(c.at), loop.end());
    loop.push_back(loop.front());
    p.points = simplify(loop);
  }
  return p;
}

}  // namespace hybridctl::toolpaths::pocket
