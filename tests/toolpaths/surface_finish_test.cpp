// Surface finishing of ball and bull-nose cutters (docs/toolpaths.md, "Surface finishing"),
// judged on designs whose surface is known in closed form: blocks whose tops are a smooth
// bump, a sloped face and a round trough (a concave fillet), triangulated on a 0.5 mm
// grid. The part the toolpath
// makes is computed from the moves themselves (the cutter's lower surface swept along
// every feed move) and compared with the STL's heights: no point of any move puts the
// cutter under the STL, and what stays over it is at most the scallop asked for.

#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "geometry/shapes.hpp"
#include "geometry/voxelize.hpp"
#include "toolpaths/drop_cutter.hpp"
#include "toolpaths/pocket_path.hpp"
#include "toolpath_oracles.hpp"

namespace hybridctl::toolpaths {
namespace {

using geometry::Solid;
using geometry::Triangle;
using geometry::Vec3;

constexpr double kSide = 30, kGrid = 0.5;
const geometry::Lattice kLattice{0.5, {0, 0, 0}};

// The designs' top faces, z over (x, y), all under the stock's top at 8 mm.
using Height = double (*)(double, double);
// A smooth dome, 22 degrees at its steepest.
double bump(double x, double y) { return 5 + 3 * std::exp(-((x - 15) * (x - 15) + (y - 15) * (y - 15)) / 40); }
// A plane sloping 10 degrees across the rows (along Y).
double slope(double, double y) { return 2 + 0.18 * y; }
// A round trough along Y, concave as a fillet between two faces is: radius 12, 3 deep,
// its sides 41 degrees steep at the rim. (Steeper, the grid's last facet before the rim
// makes a crease with the one under it that no ball fits into: what stays there is the
// STL's, not the toolpath's.)
double trough(double x, double) {
  const double u = x - 15;
  return std::abs(u) >= std::sqrt(63.0) ? 7 : 7 - (std::sqrt(144 - u * u) - 9);
}

// The STL's height over (x, y): the grid's triangles split along each cell's diagonal.
double mesh_height(Height surface, double x, double y) {
  const int i = std::clamp(int(std::floor(x / kGrid)), 0, int(kSide / kGrid) - 1);
  const int j = std::clamp(int(std::floor(y / kGrid)), 0, int(kSide / kGrid) - 1);
  const double x0 = i * kGrid, y0 = j * kGrid, u = (x - x0) / kGrid, v = (y - y0) / kGrid;
  const double z00 = surface(x0, y0), z10 = surface(x0 + kGrid, y0), z01 = surface(x0, y0 + kGrid),
               z11 = surface(x0 + kGrid, y0 + kGrid);
  return u >= v ? z00 + u * (z10 - z00) + v * (z11 - z10) : z00 + v * (z01 - z00) + u * (z11 - z01);
}

std::vector<Triangle> block_under(Height surface) {
  std::vector<Triangle> t;
  const int n = int(kSide / kGrid);
  auto top = [surface](int i, int j) { return Vec3{i * kGrid, j * kGrid, surface(i * kGrid, j * kGrid)}; };
  auto low = [](int i, int j) { return Vec3{i * kGrid, j * kGrid, 0}; };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      t.push_back({top(i, j), top(i + 1, j), top(i + 1, j + 1)});
      t.push_back({top(i, j), top(i + 1, j + 1), top(i, j + 1)});
      t.push_back({low(i, j), low(i + 1, j + 1), low(i + 1, j)});
      t.push_back({low(i, j), low(i, j + 1), low(i + 1, j + 1)});
    }
  for (int k = 0; k < n; ++k) {
    t.push_back({low(k, 0), low(k + 1, 0), top(k + 1, 0)});  // y = 0, facing -Y
    t.push_back({low(k, 0), top(k + 1, 0), top(k, 0)});
    t.push_back({low(k, n), top(k + 1, n), low(k + 1, n)});  // y = 30, facing +Y
    t.push_back({low(k, n), top(k, n), top(k + 1, n)});
    t.push_back({low(0, k), top(0, k + 1), low(0, k + 1)});  // x = 0, facing -X
    t.push_back({low(0, k), top(0, k), top(0, k + 1)});
    t.push_back({low(n, k), low(n, k + 1), top(n, k + 1)});  // x = 30, facing +X
    t.push_back({low(n, k), top(n, k + 1), top(n, k)});
  }
  return t;
}

config::CuttingTool cutter(config::ToolType type, double diameter, double corner) {
  config::CuttingTool t;
  t.number = 3;
  t.name = "finisher";
  t.type = type;
  t.diameter = diameter;
  t.corner_radius = corner;
  t.flute_length = 14;
  t.shank = {diameter, 30};
  t.holder = {30, 40};
  t.feed = 1200;
  t.plunge_feed = 300;
  t.step_down = 1;
  t.step_over = 3;
  return t;
}

config::Setup top_setup() {
  config::Setup s;
  s.name = "top";
  s.approach = config::Approach::PlusZ;
  return s;
}

struct Made {
  double gouge = 0;   // deepest point of the cutter under the STL, along any move (mm)
  double excess = 0;  // most material left over the STL within [4, 26]^2, along its normal (mm)
  int passes = 0;
  Vec3 worst;          // the tip where the gouge is deepest
  Vec3 excess_at;      // where the excess is highest (x, y)
  int worst_move = 0;
};

// The part made: the stock's top (8 mm, over the face) cut down by the cutter's lower
// surface at every point of every feed move (sampled every 0.02 mm), looked at on a 0.25
// mm grid over [4, 26]^2; the gouge at every sample of every move (rapids included).
Made measure(const Toolpath& p, const CutterShape& shape, Height surface) {
  const int n = int(22 / 0.25) + 1;
  std::vector<double> made(std::size_t(n) * std::size_t(n), 8.0);
  Made out;
  const auto starts = testing::move_starts(p);
  for (std::size_t i = 0; i < p.moves.size(); ++i) {
    const auto& m = p.moves[i];
    if (m.comment.find("surface finishing") != std::string::npos || m.comment == "down to the surface") ++out.passes;
    testing::along(starts[i], m.to, 0.02, [&](Vec3 q) {
      // Gouge: the lower surface on a polar grid around the axis, against the STL.
      for (int r = 0; r <= 8; ++r)
        for (int a = 0; a < (r == 0 ? 1 : 24); ++a) {
          const double d = shape.radius * r / 8, ang = 2 * M_PI * a / 24;
          const double x = q.x + d * std::cos(ang), y = q.y + d * std::sin(ang);
          if (x < 0 || y < 0 || x > kSide || y > kSide) continue;
          const double g = mesh_height(surface, x, y) - (q.z + shape.height_at(d));
          if (g > out.gouge) out.worst = q, out.worst_move = int(i);
          out.gouge = std::max(out.gouge, g);
        }
      if (m.kind == MoveKind::Rapid) return;
      const int i0 = std::max(0, int(std::ceil((q.x - shape.radius - 4) / 0.25)));
      const int i1 = std::min(n - 1, int(std::floor((q.x + shape.radius - 4) / 0.25)));
      const int j0 = std::max(0, int(std::ceil((q.y - shape.radius - 4) / 0.25)));
      const int j1 = std::min(n - 1, int(std::floor((q.y + shape.radius - 4) / 0.25)));
      for (int j = j0; j <= j1; ++j)
        for (int k = i0; k <= i1; ++k) {
          const double d = std::hypot(4 + k * 0.25 - q.x, 4 + j * 0.25 - q.y);
          if (d <= shape.radius) {
            double& z = made[std::size_t(j) * std::size_t(n) + std::size_t(k)];
            z = std::min(z, q.z + shape.height_at(d));
          }
        }
    });
  }
  for (int j = 0; j < n; ++j)
    for (int k = 0; k < n; ++k) {
      // Along the surface's normal, as exact verification measures it: the height over
      // the STL times the cosine of its slope there.
      const double x = 4 + k * 0.25, y = 4 + j * 0.25, d = 0.01;
      const double gx = (mesh_height(surface, x + d, y) - mesh_height(surface, x - d, y)) / (2 * d);
      const double gy = (mesh_height(surface, x, y + d) - mesh_height(surface, x, y - d)) / (2 * d);
      const double e = (made[std::size_t(j) * std::size_t(n) + std::size_t(k)] - mesh_height(surface, x, y)) /
                       std::sqrt(1 + gx * gx + gy * gy);
      if (e > out.excess) out.excess = e, out.excess_at = {4 + k * 0.25, 4 + j * 0.25, 0};
    }
  return out;
}

struct Case {
  const char* name;
  config::CuttingTool tool;
  Height surface = bump;
};

class SurfaceFinishing : public ::testing::TestWithParam<Case> {};

TEST_P(SurfaceFinishing, CutsTheFaceToTheScallopAskedForAndNeverUnderIt) {
  const auto mesh = std::make_shared<const std::vector<Triangle>>(block_under(GetParam().surface));
  const Solid design = geometry::voxelize(geometry::TriangleMesh{*mesh}, kLattice, "bump block");
  const Solid stock = geometry::make_box(kLattice, {{0, 0, 0}, {kSide, kSide, 8}});
  const Solid roi = geometry::subtract(stock, design);
  const config::CuttingTool tool = GetParam().tool;
  PocketOptions on;
  on.design = mesh;
  on.scallop = 0.02;
  PocketOptions off = on;
  off.finish_surfaces = false;
  const CutterShape shape = cutter_shape(tool);

  const Made finished = measure(pocket_path(roi, design, stock, tool, top_setup(), on), shape, GetParam().surface);
  const Made levels = measure(pocket_path(roi, design, stock, tool, top_setup(), off), shape, GetParam().surface);
  EXPECT_GT(finished.passes, 0);
  // Never under the STL, roughing included: the drop-cutter's contact is exact, the
  // chords between its points refined to 0.0005 mm (plus the oracle's own sampling), and
  // the roughing's tips stand off the STL between the lattice's centres too.
  EXPECT_LE(finished.gouge, 0.001) << "move " << finished.worst_move << " at (" << finished.worst.x << ", "
                                   << finished.worst.y << ", " << finished.worst.z << ")";
  // Along the surface's normal: the scallop asked for, 0.02 mm on a flat face (wider
  // where a slope runs across the rows: by 1 / cos of it), plus the path's thinning
  // (0.002 mm vertically) and what the facets' creases leave (the ball on the bump 0.028).
  EXPECT_LE(finished.excess, 0.03) << "at (" << finished.excess_at.x << ", " << finished.excess_at.y << ")";
  // The Z-levels alone leave their staircase: a step-down's worth, less the cutter's
  // curve (and they keep off the design's voxels, not its STL).
  EXPECT_GT(levels.excess, 0.2);
}

INSTANTIATE_TEST_SUITE_P(Cutters, SurfaceFinishing,
                         ::testing::Values(Case{"BumpBall6", cutter(config::ToolType::Ball, 6, 3)},
                                           Case{"BumpBull8r1", cutter(config::ToolType::Bull, 8, 1)},
                                           Case{"SlopeBall6", cutter(config::ToolType::Ball, 6, 3), slope},
                                           Case{"TroughBall6", cutter(config::ToolType::Ball, 6, 3), trough}),
                         [](const auto& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace hybridctl::toolpaths
