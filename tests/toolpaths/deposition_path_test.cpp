// Raster deposition, as a specification: what a deposition toolpath must and must not do.
// The checks read the moves back (no knowledge of the generator's insides): every
// deposition segment lies in the ROI slice of its layer, layers go bottom-up with the
// raster turning between them, travel never descends into material, and deposit with
// nothing below it is reported.

#include "toolpaths/deposition_path.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <numbers>
#include <set>

#include "toolpaths/setup_frame.hpp"
#include "geometry/shapes.hpp"
#include "geometry/voxelize.hpp"
#include "toolpath_oracles.hpp"
#include "../geometry/mesh_fixtures.hpp"

namespace hybridctl::toolpaths {
namespace {

using geometry::Box3;
using geometry::Index3;
using geometry::Lattice;
using geometry::make_box;
using geometry::Solid;
using geometry::Vec3;
using testing::along;
using testing::move_starts;

const Lattice kLattice{0.5, {0, 0, 0}};

config::AdditiveHead ded_head() {
  config::AdditiveHead h;
  h.name = "ded";
  h.bead = {config::BeadShape::Ellipsoid, 1.5, 0.75};
  h.layer_height = 0.6;
  h.hatch_spacing = 1.05;
  h.travel_clearance = 5;
  h.feed = 800;
  return h;
}

config::Setup top_setup() {
  config::Setup s;
  s.name = "top";
  s.approach = config::Approach::PlusZ;
  return s;
}

Solid box(Box3 b) { return make_box(kLattice, b); }

// The ROI voxel layers a deposition layer at height z_bottom stands for: those whose
// centres lie in its band [z_bottom, z_bottom + layer_height).
std::vector<int> layer_slices(double z_bottom, double layer_height) {
  const double h = kLattice.voxel_size;
  std::vector<int> out;
  for (int k = int(std::floor(z_bottom / h)) - 1; (k + 0.5) * h < z_bottom + layer_height - 1e-9; ++k)
    if ((k + 0.5) * h >= z_bottom - 1e-9) out.push_back(k);
  if (out.empty()) out.push_back(int(std::floor((z_bottom + layer_height / 2) / h)));
  return out;
}

// Within half a voxel (sideways) of a voxel of `solid` in one of the layers `ks`.
bool near_slice(const Solid& solid, Vec3 p, const std::vector<int>& ks) {
  const double h = kLattice.voxel_size;
  for (int k : ks)
    for (double dx : {-h / 2, 0.0, h / 2})
      for (double dy : {-h / 2, 0.0, h / 2})
        if (solid.contains({int(std::floor((p.x + dx) / h)), int(std::floor((p.y + dy) / h)), k})) return true;
  return false;
}

struct Segment {
  Vec3 a, b;
};
std::vector<Segment> deposition_segments(const Toolpath& p) {
  std::vector<Segment> out;
  const auto starts = move_starts(p);
  for (std::size_t i = 0; i < p.moves.size(); ++i)
    if (p.moves[i].process_on) out.push_back({starts[i], p.moves[i].to});
  return out;
}

void expect_segments_in_region(const Toolpath& p, const Solid& roi, double layer_height) {
  const auto segments = deposition_segments(p);
  ASSERT_FALSE(segments.empty());
  int outside = 0;
  for (const Segment& s : segments) {
    ASSERT_DOUBLE_EQ(s.a.z, s.b.z) << "deposition moves are level";
    const std::vector<int> ks = layer_slices(s.a.z, layer_height);
    along(s.a, s.b, kLattice.voxel_size / 8, [&](Vec3 q) {
      if (!near_slice(roi, q, ks) && ++outside <= 5)
        ADD_FAILURE() << "deposit at (" << q.x << ", " << q.y << ", " << q.z << ") is outside the ROI layers "
                      << ks.front() << ".." << ks.back();
    });
  }
  EXPECT_EQ(outside, 0);
}

// How many heights the deposition moves lie at.
std::size_t layer_count(const Toolpath& p) {
  std::set<double> heights;
  for (const Segment& s : deposition_segments(p)) heights.insert(s.a.z);
  return heights.size();
}

bool has_warning(const Toolpath& p, const std::string& word) {
  for (const auto& w : p.warnings)
    if (w.find(word) != std::string::npos) return true;
  return false;
}

TEST(DepositionPath, RecordsTheHeadSetupAndFeeds) {
  const Solid roi = box({{2, 2, 0}, {8, 6, 2}});
  DepositionOptions o;
  o.fallback_tool_number = 101;
  const Toolpath p = deposition_path(roi, Solid(kLattice, {}), ded_head(), top_setup(), o);
  EXPECT_EQ(p.process, Process::Deposition);
  EXPECT_EQ(p.instrument, "ded");
  EXPECT_EQ(p.setup, "top");
  EXPECT_EQ(p.tool_number, 101) << "a head without a tool number takes the fallback";
  auto numbered = ded_head();
  numbered.tool_number = 105;
  EXPECT_EQ(deposition_path(roi, Solid(kLattice, {}), numbered, top_setup(), o).tool_number, 105);
  ASSERT_FALSE(p.moves.empty());
  EXPECT_EQ(p.moves.front().kind, MoveKind::Rapid);
  EXPECT_EQ(p.moves.front().to, p.start);
  EXPECT_DOUBLE_EQ(p.start.z, p.safe_z);
  for (const auto& m : p.moves) {
    if (m.process_on) {
      EXPECT_EQ(m.kind, MoveKind::Feed);
      EXPECT_DOUBLE_EQ(m.feed, 800);
    }
    EXPECT_LE(m.to.z, p.safe_z + 1e-9);
  }
  EXPECT_DOUBLE_EQ(p.moves.back().to.z, p.safe_z);
}

TEST(DepositionPath, SegmentsLieInTheirLayersRegion) {
  // An L-shaped wall on a base plate, with a hole: rasters must break at the hole.
  const Solid base = box({{0, 0, 0}, {20, 16, 2}});
  Solid roi = geometry::unite(box({{1, 1, 2}, {19, 5, 6}}), box({{1, 1, 2}, {6, 15, 4.5}}));
  roi = geometry::subtract(roi, box({{9, 2, 2}, {12, 4, 6}}));
  const auto head = ded_head();
  const Toolpath p = deposition_path(roi, base, head, top_setup());
  expect_segments_in_region(p, roi, head.layer_height);
  EXPECT_FALSE(has_warning(p, "overhang")) << (p.warnings.empty() ? "" : p.warnings.front());
}

TEST(DepositionPath, ContourPassesStayInTheRegionToo) {
  const Solid roi = make_box(kLattice, {{2, 2, 0}, {14, 10, 1.8}});
  const auto head = ded_head();
  DepositionOptions o;
  o.contour = ContourPass::BeforeInfill;
  const Toolpath with = deposition_path(roi, Solid(kLattice, {}), head, top_setup(), o);
  DepositionOptions rasters_only;
  rasters_only.contour = ContourPass::None;
  const Toolpath without = deposition_path(roi, Solid(kLattice, {}), head, top_setup(), rasters_only);
  expect_segments_in_region(with, roi, head.layer_height);
  EXPECT_GT(deposition_segments(with).size(), deposition_segments(without).size());
  // The contour comes first in a layer: the first deposition moves turn corners.
  const auto segs = deposition_segments(with);
  std::set<std::pair<int, int>> directions;
  for (std::size_t i = 0; i < 4 && i < segs.size(); ++i)
    directions.insert({int(std::round(segs[i].b.x - segs[i].a.x > 0 ? 1 : segs[i].b.x < segs[i].a.x ? -1 : 0)),
                       int(std::round(segs[i].b.y - segs[i].a.y > 0 ? 1 : segs[i].b.y < segs[i].a.y ? -1 : 0))});
  EXPECT_GE(directions.size(), 3u);
}

// A wall whose faces run through voxel centres (y = 2.25 and 4.75 on 0.5 mm voxels): the
// voxel region holds the centres on the faces, and on the voxels alone the contour is
// pulled out to cover them, its bead past the faces. Given the design, a near-net
// deposit's beads end on its real faces: along them every bead's axis is at least half a
// bead inside. At the corners the bead stands a little past them so as to reach the
// corner itself (toolpaths/near_net_contour.hpp, corners_reaching).
TEST(DepositionPath, ANearNetDepositsBeadsEndOnTheDesignsRealWalls) {
  const geometry::TriangleMesh wall = geometry::testing::box_mesh({2.25, 2.25, 0}, {14.75, 4.75, 1.8});
  const Solid roi = make_box(kLattice, {{2, 2, 0}, {15, 5, 1.8}});  // the voxels whose centres lie in the wall
  const auto head = ded_head();
  const double half_bead = head.bead.width / 2;
  const auto worst_past_a_face = [&](const Toolpath& p) {
    double worst = -1e9;
    for (const Segment& s : deposition_segments(p))
      along(s.a, s.b, 0.05, [&](Vec3 q) {
        if (q.x > 2.25 + 2 * half_bead && q.x < 14.75 - 2 * half_bead)
          worst = std::max({worst, 2.25 - (q.y - half_bead), (q.y + half_bead) - 4.75});
      });
    return worst;
  };
  const auto farthest_corner = [&](const Toolpath& p) {
    double worst = 0;
    for (Vec3 corner : {Vec3{2.25, 2.25, 0}, Vec3{2.25, 4.75, 0}, Vec3{14.75, 2.25, 0}, Vec3{14.75, 4.75, 0}}) {
      double best = 1e9;
      for (const Segment& s : deposition_segments(p))
        along(s.a, s.b, 0.01, [&](Vec3 q) { best = std::min(best, std::hypot(q.x - corner.x, q.y - corner.y)); });
      worst = std::max(worst, best);
    }
    return worst;
  };
  DepositionOptions on_voxels;
  const Toolpath voxels = deposition_path(roi, Solid(kLattice, {}), head, top_setup(), on_voxels);
  EXPECT_GT(worst_past_a_face(voxels), 0.05) << "on the voxels the bead stands past the faces";
  DepositionOptions near_net;
  near_net.near_net_design = std::make_shared<const std::vector<geometry::Triangle>>(wall.triangles);
  const Toolpath exact = deposition_path(roi, Solid(kLattice, {}), head, top_setup(), near_net);
  EXPECT_LE(worst_past_a_face(exact), 0.002);
  EXPECT_LE(farthest_corner(exact), half_bead + 0.01) << "every corner within the bead";
  // It still lays the wall: every layer, with its contour and rasters.
  EXPECT_GE(layer_count(exact), layer_count(voxels));
  EXPECT_GE(deposition_segments(exact).size(), deposition_segments(voxels).size() / 2);
  expect_segments_in_region(exact, roi, head.layer_height);
}

// A blade 2.5 mm thick at 60 degrees to X on a plate, as the bladed disc's: on 0.5 mm
// voxels its faces are staircases, and the voxel contour zigzags inside it and left one
// face's bead out (0.754 mm short on the disc as deposited). Near-net, every layer from the
// plate up, the one whose band holds the plate's top included, has a bead's axis within
// half a bead (less the slack) of every point of both faces.
TEST(DepositionPath, ANearNetDepositLaysBothFacesOfABladeAcrossTheGrid) {
  const double c = std::cos(std::numbers::pi / 3), s = std::sin(std::numbers::pi / 3);
  const Vec3 from{6, 3, 0}, to{6 + 14 * c, 3 + 14 * s, 0};
  const geometry::TriangleMesh design = geometry::testing::joined(
      geometry::testing::box_mesh({0, 0, 0}, {20, 20, 2}), geometry::testing::bar_mesh(from, to, 2.5, 2, 6));
  const Solid roi = geometry::voxelize(design, kLattice, "design");
  const double half_bead = ded_head().bead.width / 2, slack = 0.125;
  DepositionOptions near_net;
  near_net.near_net_design = std::make_shared<const std::vector<geometry::Triangle>>(design.triangles);
  near_net.near_net_slack = slack;
  const Toolpath p = deposition_path(roi, Solid(kLattice, {}), ded_head(), top_setup(), near_net);
  std::map<double, std::vector<Segment>> layers;
  for (const Segment& seg : deposition_segments(p)) layers[std::round(seg.a.z * 1e6) / 1e6].push_back(seg);
  const auto farthest_face_point = [&](const std::vector<Segment>& segs) {
    const Vec3 n{-s * 1.25, c * 1.25, 0};
    double worst = 0;
    for (double t = 1.5; t <= 12.5; t += 0.1)
      for (double side : {-1.0, 1.0}) {
        const Vec3 q{from.x + t * c + side * n.x, from.y + t * s + side * n.y, 0};
        double best = 1e9;
        for (const Segment& seg : segs)
          along(seg.a, seg.b, 0.02, [&](Vec3 a) { best = std::min(best, std::hypot(a.x - q.x, a.y - q.y)); });
        worst = std::max(worst, best);
      }
    return worst;
  };
  int blade_layers = 0;
  for (const auto& [z, segs] : layers) {
    if (z + 0.6 <= 2 + 1e-9) continue;  // the plate's layers
    ++blade_layers;
    EXPECT_LE(farthest_face_point(segs), half_bead - slack + 0.01) << "layer at z = " << z;
  }
  EXPECT_EQ(blade_layers, 7) << "the layers from 1.8 (its band holds the plate's top) to 5.4";
}

// The head's 0.6 mm layers over a wall 2 mm tall: 0.6, 1.2, 1.8, and the last bead's top
// 0.55 mm over the wall. A near-net deposit takes four layers of 0.5 mm instead, the last
// one laid so that its crests stand just over the top.
TEST(DepositionPath, ANearNetDepositsLayersEndOnItsTop) {
  const geometry::TriangleMesh wall = geometry::testing::box_mesh({2.25, 2.25, 0}, {14.75, 6.75, 2});
  const Solid roi = make_box(kLattice, {{2, 2, 0}, {15, 7, 2}});
  DepositionOptions near_net;
  near_net.near_net_design = std::make_shared<const std::vector<geometry::Triangle>>(wall.triangles);
  const Toolpath p = deposition_path(roi, Solid(kLattice, {}), ded_head(), top_setup(), near_net);
  std::set<double> heights;
  for (const Segment& s : deposition_segments(p)) heights.insert(std::round(s.a.z * 1e6) / 1e6);
  // Four layers of 0.5 mm instead of 0.6; the last is laid lower, so that its tracks'
  // crests (0.75 mm over it) stand over the top by half the dip where two tracks a hatch
  // apart meet (an ellipse 1.5 wide, 0.375 over its middle, at 0.525 mm off its axis), not
  // by the beads' overlap (0.25 mm).
  const double dip = 0.375 * (1 - std::sqrt(1 - 0.7 * 0.7));
  const std::vector<double> z(heights.begin(), heights.end());
  ASSERT_EQ(z.size(), 4u);
  EXPECT_EQ(std::vector<double>(z.begin(), z.begin() + 3), (std::vector<double>{0, 0.5, 1.0}));
  EXPECT_NEAR(z[3] + 0.75, 2 + dip / 2, 1e-6);
}

TEST(DepositionPath, LayersGoBottomUpAtTheLayerHeight) {
  const Solid base = box({{0, 0, 0}, {12, 12, 1}});
  const Solid roi = box({{2, 2, 1}, {10, 10, 5}});
  const auto head = ded_head();
  const Toolpath p = deposition_path(roi, base, head, top_setup());
  std::vector<double> layer_z;
  double last = -1e9;
  for (const auto& s : deposition_segments(p)) {
    EXPECT_GE(s.a.z, last - 1e-9) << "a layer below one already deposited";
    if (s.a.z > last + 1e-9) layer_z.push_back(s.a.z);
    last = s.a.z;
  }
  ASSERT_GE(layer_z.size(), 6u);
  EXPECT_NEAR(layer_z.front(), 1.0, 1e-9) << "the first layer lies on the ROI's bottom face";
  for (std::size_t i = 1; i < layer_z.size(); ++i) EXPECT_NEAR(layer_z[i] - layer_z[i - 1], head.layer_height, 1e-9);
  // 4 mm of ROI at 0.6 mm layers: the layer whose middle is still inside is the last.
  EXPECT_NEAR(layer_z.back(), 1.0 + 6 * 0.6, 1e-9);
}

TEST(DepositionPath, EveryVoxelLayerOfTheRoiBelongsToADepositionLayer) {
  // 0.6 mm layers on 0.5 mm voxels: the band [1.2, 1.8) holds the centres of voxel layers
  // 2 and 3. A flange one voxel thick in layer 2 (z 1.0..1.5) must be deposited with that
  // band, not lost between the voxel layers the bands' middles fall in. It rests on existing
  // material around the core (a flange over air would not be laid).
  const Solid roi = geometry::unite(box({{4, 4, 0}, {12, 12, 2}}), box({{0, 0, 1}, {16, 16, 1.5}}));
  const Solid under_flange = geometry::subtract(box({{0, 0, 0}, {16, 16, 1}}), box({{4, 4, 0}, {12, 12, 1}}));
  const auto head = ded_head();
  const Toolpath p = deposition_path(roi, under_flange, head, top_setup());
  expect_segments_in_region(p, roi, head.layer_height);
  double flange = 0;  // mm of deposition outside the core's footprint
  for (const auto& s : deposition_segments(p))
    along(s.a, s.b, 0.05, [&](Vec3 q) {
      if (q.x < 3.5 || q.x > 12.5 || q.y < 3.5 || q.y > 12.5) flange += 0.05;
    });
  EXPECT_GT(flange, 50);
}

double direction_deg(const Segment& s) {
  double a = std::atan2(s.b.y - s.a.y, s.b.x - s.a.x) * 180 / std::numbers::pi;
  while (a < 0) a += 180;
  while (a >= 180) a -= 180;
  return a;
}

TEST(DepositionPath, RasterDirectionAlternatesBetweenLayers) {
  const Solid roi = box({{0, 0, 0}, {10, 8, 3}});
  DepositionOptions o;
  o.contour = ContourPass::None;  // the rasters' own directions
  const Toolpath p = deposition_path(roi, Solid(kLattice, {}), ded_head(), top_setup(), o);
  std::map<double, std::set<int>> by_layer;
  for (const auto& s : deposition_segments(p)) by_layer[s.a.z].insert(int(std::lround(direction_deg(s))) % 180);
  ASSERT_GE(by_layer.size(), 4u);
  int previous = -1;
  for (const auto& [z, dirs] : by_layer) {
    ASSERT_EQ(dirs.size(), 1u) << "one raster direction per layer at z=" << z;
    const int d = *dirs.begin();
    EXPECT_TRUE(d == 0 || d == 90);
    if (previous >= 0) {
      EXPECT_NE(d, previous) << "layer at z=" << z << " repeats the previous direction";
    }
    previous = d;
  }
}

TEST(DepositionPath, ArbitraryRasterAnglesFollowTheOptions) {
  const Solid roi = geometry::make_cylinder(kLattice, geometry::Axis::Z, {10, 10, 0}, 7, 2.4);
  const auto head = ded_head();
  DepositionOptions o;
  o.raster_angles_deg = {30, 120, 210};
  o.contour = ContourPass::None;  // the rasters' own directions
  const Toolpath p = deposition_path(roi, Solid(kLattice, {}), head, top_setup(), o);
  expect_segments_in_region(p, roi, head.layer_height);
  std::map<double, std::set<int>> by_layer;
  for (const auto& s : deposition_segments(p)) by_layer[s.a.z].insert(int(std::lround(direction_deg(s))));
  ASSERT_EQ(by_layer.size(), 4u);
  const int expected[] = {30, 120, 30, 30};  // 210 runs along 30
  int i = 0;
  for (const auto& [z, dirs] : by_layer) {
    EXPECT_EQ(dirs, std::set<int>{expected[i]}) << "layer " << i;
    ++i;
  }
  // Parallel lines at the hatch spacing: neighbouring 30-degree lines of the first layer.
  std::set<long> offsets;
  const double nx = -std::sin(30 * std::numbers::pi / 180), ny = std::cos(30 * std::numbers::pi / 180);
  for (const auto& s : deposition_segments(p))
    if (std::abs(s.a.z - by_layer.begin()->first) < 1e-9) offsets.insert(std::lround((s.a.x * nx + s.a.y * ny) * 1000));
  ASSERT_GE(offsets.size(), 10u);
  for (auto it = std::next(offsets.begin()); it != offsets.end(); ++it)
    EXPECT_NEAR((*it - *std::prev(it)) / 1000.0, head.hatch_spacing, 2e-3);
}

// The surface under (x, y) before a move: existing voxels and the layers deposited so
// far (layer_height each, on the columns of their region).
TEST(DepositionPath, NoRapidDescendsIntoMaterial) {
  // Two pads on either side of a tall existing wall, on a stepped base; 0.45 mm layers
  // put layer bottoms just under some voxel faces, where the bead is laid into the
  // existing surface and the head must come down the last bit at feed.
  const Solid base = geometry::unite(box({{0, 0, 0}, {30, 12, 1}}), box({{0, 0, 1}, {6, 12, 2}}));
  const Solid wall = box({{13, 0, 1}, {16, 12, 12}});
  const Solid existing = geometry::unite(base, wall);
  const Solid roi = geometry::unite(geometry::subtract(box({{1, 1, 1}, {11, 11, 3}}), existing), box({{18, 1, 1}, {28, 11, 2.5}}));
  auto head = ded_head();
  head.layer_height = 0.45;
  const Toolpath p = deposition_path(roi, existing, head, top_setup());
  expect_segments_in_region(p, roi, head.layer_height);

  const double h = kLattice.voxel_size;
  std::map<std::pair<int, int>, double> deposited;  // column -> top of deposit so far
  auto inside_material = [&](Vec3 q) {
    const int x = int(std::floor(q.x / h)), y = int(std::floor(q.y / h)), z = int(std::floor(q.z / h));
    if (existing.contains({x, y, z})) return true;
    auto it = deposited.find({x, y});
    return it != deposited.end() && q.z < it->second - 1e-9;
  };
  const auto starts = move_starts(p);
  int descents = 0, feed_descents = 0, crossed_wall = 0;
  double current_layer = -1;
  std::set<std::pair<int, int>> layer_columns;
  for (std::size_t i = 0; i < p.moves.size(); ++i) {
    const auto& m = p.moves[i];
    const Vec3 a = starts[i], b = m.to;
    if (m.process_on && std::abs(b.z - current_layer) > 1e-9) {
      // A new layer: the previous one is down.
      for (auto c : layer_columns) deposited[c] = current_layer + head.layer_height;
      layer_columns.clear();
      current_layer = b.z;
    }
    if (m.process_on)
      along(a, b, h / 8, [&](Vec3 q) { layer_columns.insert({int(std::floor(q.x / h)), int(std::floor(q.y / h))}); });
    if (m.kind == MoveKind::Rapid) {
      along(a, b, h / 8, [&](Vec3 q) {
        EXPECT_FALSE(inside_material(q)) << "rapid " << i << " passes through material at (" << q.x << ", " << q.y
                                         << ", " << q.z << ")";
      });
      if (b.z < a.z) ++descents;
      // Travel across the wall clears it by the travel clearance.
      if ((a.x < 13 && b.x > 16) || (a.x > 16 && b.x < 13)) {
        ++crossed_wall;
        EXPECT_GE(std::min(a.z, b.z), 12 + head.travel_clearance - 1e-9);
      }
    }
    if (m.kind == MoveKind::Feed && !m.process_on && b.z < a.z) ++feed_descents;
  }
  EXPECT_GT(descents, 10);
  EXPECT_GT(feed_descents, 0) << "some layer bottoms lie under the stepped base's surface";
  EXPECT_GT(crossed_wall, 0);
}

TEST(DepositionPath, TravelLiftsByTheClearanceOverWhatIsBelow) {
  const Solid roi = box({{0, 0, 0}, {10, 10, 1.2}});
  const auto head = ded_head();
  const Toolpath p = deposition_path(roi, Solid(kLattice, {}), head, top_setup());
  const auto starts = move_starts(p);
  int lifts = 0;
  for (std::size_t i = 1; i < p.moves.size(); ++i) {
    const auto& m = p.moves[i];
    if (m.kind == MoveKind::Rapid && m.to.z > starts[i].z && m.to.z < p.safe_z - 1e-9) {
      ++lifts;
      // Over the deposit of the layer being laid (up to its bead height) plus clearance.
      double next_layer = 0;
      for (std::size_t j = i; j < p.moves.size(); ++j)
        if (p.moves[j].process_on) {
          next_layer = p.moves[j].to.z;
          break;
        }
      EXPECT_NEAR(m.to.z, next_layer + head.bead.height + head.travel_clearance, 1e-9);
    }
  }
  EXPECT_GT(lifts, 5);
}

TEST(DepositionPath, OverhangsAreNotLaidAndAreReported) {
  const auto head = ded_head();
  // A block on the plate (the lowest material) is supported; so is one on existing
  // material; a block in mid-air beside them is not.
  const Solid base = box({{0, 0, 0}, {10, 10, 3}});
  const Solid on_plate = box({{0, 0, 0}, {6, 6, 3}});
  const Toolpath p1 = deposition_path(on_plate, Solid(kLattice, {}), head, top_setup());
  EXPECT_FALSE(has_warning(p1, "overhang")) << (p1.warnings.empty() ? "" : p1.warnings.front());
  const Toolpath p2 = deposition_path(box({{2, 2, 3}, {8, 8, 6}}), base, head, top_setup());
  EXPECT_FALSE(has_warning(p2, "overhang")) << (p2.warnings.empty() ? "" : p2.warnings.front());
  const Toolpath p3 = deposition_path(box({{14, 2, 5}, {20, 8, 7}}), base, head, top_setup());
  ASSERT_TRUE(has_warning(p3, "overhang"));
  EXPECT_TRUE(has_warning(p3, "not deposited"));
  // A bead over air falls: nothing of the floating block is laid, and each of its layers,
  // with nothing under it, says so.
  EXPECT_TRUE(deposition_segments(p3).empty());
  int overhang_warnings = 0;
  for (const auto& w : p3.warnings) overhang_warnings += w.find("overhang") != std::string::npos;
  EXPECT_EQ(overhang_warnings, 3);  // its four voxel layers fall in three bands of 0.6 mm
  // An explicit build plate below a floating block.
  DepositionOptions o;
  o.build_plate_z = 0;
  const Toolpath p4 = deposition_path(box({{2, 2, 4}, {8, 8, 6}}), Solid(kLattice, {}), head, top_setup(), o);
  EXPECT_TRUE(has_warning(p4, "overhang"));
  o.build_plate_z = 4;
  const Toolpath p5 = deposition_path(box({{2, 2, 4}, {8, 8, 6}}), Solid(kLattice, {}), head, top_setup(), o);
  EXPECT_FALSE(has_warning(p5, "overhang"));
  // A ledge wider than its support by more than half a bead overhangs at its edge.
  const Toolpath p6 = deposition_path(box({{0, 0, 3}, {14, 10, 5}}), base, head, top_setup());
  EXPECT_TRUE(has_warning(p6, "overhang"));
  // The ledge is laid up to the head's reach beyond its support, not farther.
  double farthest = 0;
  for (const auto& s : deposition_segments(p6)) farthest = std::max({farthest, s.a.x, s.b.x});
  EXPECT_GT(farthest, 9.0);
  EXPECT_LT(farthest, 11.0);  // the ledge itself runs to 14
}

TEST(DepositionPath, RegionsNarrowerThanABeadAreDroppedWithAWarning) {
  const Solid roi = box({{0, 0, 0}, {10, 0.5, 1}});  // one voxel wide: shorter than a bead across
  DepositionOptions o;
  o.raster_angles_deg = {90};
  const Toolpath p = deposition_path(roi, Solid(kLattice, {}), ded_head(), top_setup(), o);
  EXPECT_TRUE(deposition_segments(p).empty());
  EXPECT_TRUE(has_warning(p, "dropped"));
  const Toolpath empty = deposition_path(Solid(kLattice, {}), Solid(kLattice, {}), ded_head(), top_setup());
  EXPECT_TRUE(empty.moves.empty());
  EXPECT_FALSE(empty.warnings.empty());
}

TEST(DepositionPath, RoiUnderExistingMaterialIsSkipped) {
  // A bridge of existing material over part of the ROI: out of reach from +Z.
  const Solid existing = geometry::unite(box({{0, 0, 0}, {20, 10, 1}}), box({{8, 0, 4}, {12, 10, 5}}));
  const Solid roi = box({{2, 2, 1}, {18, 8, 3}});
  const auto head = ded_head();
  const Toolpath p = deposition_path(roi, existing, head, top_setup());
  // A defect, not a warning: the part would lack that deposit (export refuses the plan).
  EXPECT_FALSE(has_warning(p, "under existing material"));
  ASSERT_FALSE(p.defects.empty());
  for (const gcode::PathDefect& d : p.defects) {
    EXPECT_EQ(d.kind, "layer_skipped");
    EXPECT_NE(d.message.find("under existing material"), std::string::npos) << d.message;
    EXPECT_NEAR(d.where.x, 10, 1.5) << "the middle of the bridged columns";
  }
  for (const auto& s : deposition_segments(p))
    along(s.a, s.b, 0.05, [&](Vec3 q) { EXPECT_FALSE(q.x > 8.01 && q.x < 11.99) << q.x; });
}

TEST(DepositionPath, RoiUnderExistingMaterialThatThePlanDoesNotCountOnIsLeftOutWithAWarning) {
  // The same bridge; the plan counts on this action for the ROI's left half only (the rest
  // an earlier action was to lay). Executed from the material present, the ROI holds both.
  const Solid existing = geometry::unite(box({{0, 0, 0}, {20, 10, 1}}), box({{8, 0, 4}, {12, 10, 5}}));
  const Solid roi = box({{2, 2, 1}, {18, 8, 3}});
  const Solid left = box({{2, 2, 1}, {7, 8, 3}});
  DepositionOptions o;
  o.counted_on = &left;
  const Toolpath p = deposition_path(roi, existing, ded_head(), top_setup(), o);
  EXPECT_TRUE(p.defects.empty()) << p.defects.front().message;
  EXPECT_TRUE(has_warning(p, "earlier actions were to lay lie under existing material")) << "said, not hidden";
  for (const auto& s : deposition_segments(p))
    along(s.a, s.b, 0.05, [&](Vec3 q) { EXPECT_FALSE(q.x > 8.01 && q.x < 11.99) << q.x; });
  // Counted on under the bridge: the defect stays.
  const Solid middle = box({{7, 2, 1}, {13, 8, 3}});
  o.counted_on = &middle;
  const Toolpath counted = deposition_path(roi, existing, ded_head(), top_setup(), o);
  ASSERT_FALSE(counted.defects.empty());
  EXPECT_EQ(counted.defects.front().kind, "layer_skipped");
}

TEST(DepositionPath, PassesThePlanDoesNotCountOnAreLeftOutWhereTheNozzleBodyWouldMeetMaterialBesideThem) {
  // A plate with an 11 mm wall on it, a pad far from the wall and one right beside it. The
  // nozzle (10 mm across, its tip 3 mm over the bead's bottom) coming down to the near pad
  // would meet the wall. When an earlier action was to lay the near pad (the plan does not
  // count on this one for it), its passes are left out with a warning; when the plan
  // counts on this action for it, they stay: keeping those clear is the planner's
  // (planner/atoms/deposit_reach.hpp), and the simulated machine stops on them.
  const Solid existing = geometry::unite(box({{0, 0, 0}, {30, 10, 1}}), box({{14, 0, 1}, {16, 10, 12}}));
  const Solid far_pad = box({{2, 2, 1}, {6, 8, 2}}), near_pad = box({{17, 2, 1}, {20, 8, 2}});
  const Solid roi = geometry::unite(far_pad, near_pad);
  auto head = ded_head();
  head.nozzle = config::Nozzle{10, 40, 3};
  DepositionOptions o;
  o.counted_on = &far_pad;
  const Toolpath p = deposition_path(roi, existing, head, top_setup(), o);
  EXPECT_TRUE(has_warning(p, "nozzle body over them would meet material")) << "said, not hidden";
  bool far_laid = false;
  for (const auto& s : deposition_segments(p))
    along(s.a, s.b, 0.05, [&](Vec3 q) {
      EXPECT_LT(q.x, 16) << "a pass beside the wall";
      far_laid = far_laid || q.x < 6;
    });
  EXPECT_TRUE(far_laid);
  o.counted_on = &roi;
  const Toolpath counted = deposition_path(roi, existing, head, top_setup(), o);
  EXPECT_FALSE(has_warning(counted, "nozzle body"));
  bool near_laid = false;
  for (const auto& s : deposition_segments(counted)) along(s.a, s.b, 0.05, [&](Vec3 q) { near_laid = near_laid || q.x > 17; });
  EXPECT_TRUE(near_laid);
}

TEST(DepositionPath, OtherSetupsWorkInTheirWorkFrame) {
  // Deposit from below (approach -Z): in the part frame the layers grow downwards.
  const Solid existing = box({{0, 0, 5}, {10, 10, 8}});
  const Solid roi = box({{2, 2, 2}, {8, 8, 5}});
  config::Setup bottom;
  bottom.name = "bottom";
  bottom.approach = config::Approach::MinusZ;
  const auto head = ded_head();
  const Toolpath p = deposition_path(roi, existing, head, bottom);
  EXPECT_EQ(p.setup, "bottom");
  expect_segments_in_region(p, part_to_work(roi, bottom.approach), head.layer_height);
  EXPECT_FALSE(has_warning(p, "overhang"));
  double previous = 1e9;
  for (const auto& s : deposition_segments(p)) {
    const Vec3 q = work_to_part(s.a, bottom.approach);
    EXPECT_LE(q.z, previous + 1e-9) << "part-frame layers go down from the existing block";
    previous = q.z;
    EXPECT_TRUE(roi.contains({int(std::floor(q.x / 0.5)), int(std::floor(q.y / 0.5)), int(std::floor((q.z - 0.3) / 0.5))}));
  }
}

}  // namespace
}  // namespace hybridctl::toolpaths
