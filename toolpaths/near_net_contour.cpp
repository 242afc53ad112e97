#include "toolpaths/near_net_contour.hpp"

#include <algorithm>
#include <cmath>

namespace hybridctl::toolpaths {
namespace {

double length_of(const std::vector<Point2>& line) {
  double length = 0;
  for (std::size_t i = 1; i < line.size(); ++i)
    length += std::hypot(line[i].x - line[i - 1].x, line[i].y - line[i - 1].y);
  return length;
}

Cell cell_of(Point2 p, const geometry::Lattice& lattice) {
  const double h = lattice.voxel_size;
  return {int(std::floor((p.x - lattice.origin.x) / h)), int(std::floor((p.y - lattice.origin.y) / h))};
}

// The points of a loop (`closed`) or an open line with every edge cut into steps of at
// most `step`, so that each part of it is tested against the cells.
std::vector<Point2> densified(const std::vector<Point2>& line, double step, bool closed) {
  std::vector<Point2> out;
  const std::size_t n = line.size(), edges = closed ? n : n - 1;
  for (std::size_t i = 0; n > 0 && i < edges; ++i) {
    const Point2 a = line[i], b = line[(i + 1) % n];
    const int parts = std::max(1, int(std::ceil(std::hypot(b.x - a.x, b.y - a.y) / step)));
    for (int k = 0; k < parts; ++k) out.push_back({a.x + (b.x - a.x) * k / parts, a.y + (b.y - a.y) * k / parts});
  }
  if (!closed && n > 0) out.push_back(line.back());
  return out;
}

// The runs of a closed loop's points where `keep` holds, as open polylines; the whole loop,
// closed, where it holds everywhere.
template <class Keep>
std::vector<std::vector<Point2>> kept_runs(const std::vector<Point2>& loop, Keep keep) {
  const std::size_t n = loop.size();
  std::vector<std::vector<Point2>> out;
  if (n < 2) return out;
  std::size_t start = n;  // a point not kept, where the runs begin and end
  for (std::size_t i = 0; i < n; ++i)
    if (!keep(loop[i])) {
      start = i;
      break;
    }
  if (start == n) {
    out.push_back(loop);
    out.back().push_back(loop.front());
    return out;
  }
  std::vector<Point2> run;
  for (std::size_t k = 1; k <= n; ++k) {
    const Point2 p = loop[(start + k) % n];
    if (keep(p)) {
      run.push_back(p);
    } else if (!run.empty()) {
      out.push_back(std::move(run));
      run.clear();
    }
  }
  return out;
}

// The pieces of an open polyline whose points keep holds.
template <class Keep>
std::vector<std::vector<Point2>> kept_pieces(const std::vector<Point2>& line, Keep keep) {
  std::vector<std::vector<Point2>> out;
  std::vector<Point2> piece;
  for (const Point2& p : line) {
    if (keep(p)) {
      piece.push_back(p);
    } else if (!piece.empty()) {
      out.push_back(std::move(piece));
      piece.clear();
    }
  }
  if (!piece.empty()) out.push_back(std::move(piece));
  return out;
}

// The runs of `loops` where `keep` holds and that are `min_length` long, with the cells
// they run through set in `cells` when given.
template <class Keep>
std::vector<std::vector<Point2>> runs_of(const std::vector<std::vector<Point2>>& loops, Keep keep,
                                         const geometry::Lattice& lattice, double min_length, SliceMask* cells) {
  std::vector<std::vector<Point2>> out;
  for (const auto& loop : loops)
    for (auto& run : kept_runs(densified(loop, lattice.voxel_size / 2, true), keep)) {
      if (run.size() < 2 || length_of(run) < min_length - 1e-9) continue;
      if (cells)
        for (const Point2& p : run) {
          const Cell c = cell_of(p, lattice);
          cells->set(c.x, c.y);
        }
      out.push_back(without_collinear(run));
    }
  return out;
}

}  // namespace

std::vector<Point2> corners_reaching(const std::vector<Point2>& loop, const NearNetBead& bead) {
  // A corner's sides are read from the nearest points at least this far along: Clipper
  // leaves edges of a few micrometres whose own directions turn sharply.
  constexpr double kSide = 0.05;  // mm
  const std::size_t n = loop.size();
  if (n < 3) return loop;
  const auto away = [&](std::size_t i, int step) {
    std::size_t j = i;
    for (std::size_t k = 1; k < n; ++k) {
      j = (j + n + step) % n;
      if (std::hypot(loop[j].x - loop[i].x, loop[j].y - loop[i].y) >= kSide) break;
    }
    return loop[j];
  };
  std::vector<Point2> out;
  for (std::size_t i = 0; i < n; ++i) {
    const Point2 p = away(i, -1), v = loop[i], q = away(i, +1);
    const double l1 = std::hypot(v.x - p.x, v.y - p.y), l2 = std::hypot(q.x - v.x, q.y - v.y);
    if (!(l1 > 0) || !(l2 > 0)) {  // a loop shorter than a corner's sides
      out.push_back(v);
      continue;
    }
    const Point2 e1{(v.x - p.x) / l1, (v.y - p.y) / l1}, e2{(q.x - v.x) / l2, (q.y - v.y) / l2};
    const Point2 out_dir{e1.x - e2.x, e1.y - e2.y};
    const double len = std::hypot(out_dir.x, out_dir.y);
    // The region on the right: a convex corner turns right. |e1 - e2| is 2 sin(turn / 2);
    // the design's corner lies inset / cos(turn / 2) out along the bisector. A spike's
    // corner is farther than a bead can follow: at most half a bead out.
    const bool convex = len > 1e-9 && e1.x * e2.y - e1.y * e2.x < 0;
    const double cos_half_turn = std::sqrt(std::max(0.0, 1 - len * len / 4));
    const double move = !convex                ? 0
                        : cos_half_turn > 1e-9 ? bead.axis_inset / cos_half_turn - bead.corner_reach
                                               : bead.half_width;
    if (!(move > 0)) {
      out.push_back(v);
      continue;
    }
    // Out to the corner and back, the sides left where they are: moving the vertex alone
    // would tilt them past the faces all along.
    const double m = std::min(move, bead.half_width), side = std::min({m, l1 / 2, l2 / 2});
    out.push_back({v.x - e1.x * side, v.y - e1.y * side});
    out.push_back({v.x + out_dir.x / len * m, v.y + out_dir.y / len * m});
    out.push_back({v.x + e2.x * side, v.y + e2.y * side});
  }
  return out;
}

NearNetContour near_net_contour(const TipKeepOut& axes, const SliceMask& region,
                                const std::vector<std::vector<Point2>>& voxel_chains, const geometry::Lattice& lattice,
                                const NearNetBead& bead) {
  const double h = lattice.voxel_size;
  NearNetContour out;
  out.exact_cells = SliceMask(region.x0(), region.y0(), region.nx(), region.ny());
  std::vector<std::vector<Point2>> reaching;
  for (const auto& loop : axes.loops()) reaching.push_back(corners_reaching(loop, bead));
  out.exact = runs_of(reaching, [&](Point2 p) { return region.at(cell_of(p, lattice)); }, lattice, bead.min_length,
                      &out.exact_cells);
  if (out.exact.empty()) {
    out.voxel = voxel_chains;
    return out;
  }
  // A voxel chain's point within half a bead of an exact axis is that axis's to lay (the
  // cell's half diagonal added: the mask holds the cells the axes run through).
  const SliceMask near_exact = grow_by_disc(out.exact_cells, bead.half_width / h + std::sqrt(0.5));
  const auto away_from_exact = [&](Point2 p) { return !near_exact.at(cell_of(p, lattice)); };
  for (const auto& chain : voxel_chains)
    for (auto& piece : kept_pieces(densified(chain, h / 2, false), away_from_exact))
      if (piece.size() >= 2 && length_of(piece) >= bead.min_length - 1e-9) out.voxel.push_back(without_collinear(piece));
  return out;
}

std::vector<std::vector<Point2>> near_net_gap_loops(const TipKeepOut& axes, const SliceMask& region,
                                                    const geometry::Lattice& lattice, const NearNetBead& bead,
                                                    double hatch_spacing) {
  const TipKeepOut middle = axes.grown(-bead.half_width);
  if (middle.empty()) return {};
  // Where the middle is a hatch spacing wide, rasters run across it; elsewhere it is a
  // sliver they only cross, leaving what lies between them.
  const TipKeepOut wide = middle.grown(-hatch_spacing / 2).grown(hatch_spacing / 2 + 0.02);
  return runs_of(middle.loops(),
                 [&](Point2 p) { return region.at(cell_of(p, lattice)) && (wide.empty() || !wide.contains(p)); },
                 lattice, bead.min_length, nullptr);
}

std::vector<double> near_net_section_heights(const std::vector<geometry::Triangle>& design, double zb,
                                             double layer_height, double bead_height, const geometry::Lattice& lattice) {
  constexpr double kFlat = 1e-9;  // mm: a facet whose corners differ less in z is flat
  const double top = zb + layer_height;
  const bool flat_face_within = std::any_of(design.begin(), design.end(), [&](const geometry::Triangle& t) {
    const double z = t[0].z;
    return std::abs(t[1].z - z) < kFlat && std::abs(t[2].z - z) < kFlat && z > zb + kFlat && z < top - kFlat;
  });
  if (!flat_face_within) return {zb + std::min(layer_height, bead_height / 2) / 2};
  const double h = lattice.voxel_size, oz = lattice.origin.z;
  std::vector<double> heights;
  const int k_lo = int(std::ceil((zb - oz) / h - 0.5 - 1e-9)), k_hi = int(std::ceil((top - oz) / h - 0.5 - 1e-9)) - 1;
  for (int k = k_lo; k <= k_hi; ++k) heights.push_back(oz + (k + 0.5) * h);
  if (heights.empty()) heights.push_back(zb + layer_height / 2);
  return heights;
}

}  // namespace hybridctl::toolpaths
