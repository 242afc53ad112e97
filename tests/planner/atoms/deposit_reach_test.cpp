// A head deposits towards itself, layer on layer: material already there above an atom
// (towards the head) keeps the head from it. The search leaves such actions out, so a
// column made of two deposits from opposite sides cannot be made in either order.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <memory>
#include <random>

#include "planner/atoms/deposit_reach.hpp"
#include "../planner_fixtures.hpp"

namespace hybridctl::planner {
namespace {

using geometry::Axis;
using geometry::AxisDirection;
using geometry::make_box;
using testing::make_problem;
using testing::VoxelPrimitive;
using testing::VoxelProblem;

const Lattice kUnit{1.0, {0, 0, 0}};
const IndexBox kDomain{{0, 0, 0}, {4, 1, 10}};
constexpr AxisDirection kFromAbove{Axis::Z, +1}, kFromBelow{Axis::Z, -1};

Solid slab(double z0, double z1) { return make_box(kUnit, {{0, 0, z0}, {4, 1, z1}}); }

int atom_at(const VoxelProblem& vp, int z) { return vp.atoms.atom_at({1, 0, z}); }

// Deposits of the column's lower and upper part, each from `lower_from` and `upper_from`,
// with the relation atoms_above gives each side.
VoxelProblem column(AxisDirection lower_from, AxisDirection upper_from) {
  VoxelProblem vp = make_problem({{"lower", Mode::Additive, false, 1.0, slab(0, 6)}, {"upper", Mode::Additive, false, 1.0, slab(4, 10)}},
                                 slab(0, 10), kDomain);
  vp.problem.primitives[0].blocked_by = std::make_shared<const AtomRelation>(atoms_above(vp.atoms, lower_from, 1));
  vp.problem.primitives[1].blocked_by = std::make_shared<const AtomRelation>(atoms_above(vp.atoms, upper_from, 1));
  return vp;
}

TEST(AtomsAbove, AreTheAtomsTowardsTheHeadInAColumn) {
  const VoxelProblem vp = column(kFromAbove, kFromAbove);
  ASSERT_EQ(vp.atoms.atom_count(), 3);
  const int bottom = atom_at(vp, 0), middle = atom_at(vp, 5), top = atom_at(vp, 9);
  const auto from_above = atoms_above(vp.atoms, kFromAbove, 1);
  EXPECT_TRUE(from_above[std::size_t(bottom)].test(middle));
  EXPECT_TRUE(from_above[std::size_t(bottom)].test(top));
  EXPECT_TRUE(from_above[std::size_t(middle)].test(top));
  EXPECT_FALSE(from_above[std::size_t(middle)].test(bottom));
  EXPECT_TRUE(from_above[std::size_t(top)].words().empty()) << "nothing lies above the top";
  const auto from_below = atoms_above(vp.atoms, kFromBelow, 1);
  EXPECT_TRUE(from_below[std::size_t(top)].test(bottom));
  EXPECT_TRUE(from_below[std::size_t(bottom)].words().empty());
}

TEST(AtomsAbove, LeaveOutMaterialCloserThanTheGap) {
  // Two one-voxel layers: the upper lies in the same deposition layer as the lower.
  const VoxelProblem vp =
      make_problem({{"a", Mode::Additive, false, 1.0, slab(0, 1)}, {"b", Mode::Additive, false, 1.0, slab(1, 2)}}, slab(0, 2),
                   {{0, 0, 0}, {4, 1, 2}});
  const int a = atom_at(vp, 0), b = atom_at(vp, 1);
  EXPECT_TRUE(atoms_above(vp.atoms, kFromAbove, 1)[std::size_t(a)].test(b));
  EXPECT_TRUE(atoms_above(vp.atoms, kFromAbove, 2)[std::size_t(a)].words().empty());
  EXPECT_EQ(deposit_reach_gap(0.6, 0.5), 2) << "a 0.6 mm layer holds at most two 0.5 mm voxel centres";
  EXPECT_EQ(deposit_reach_gap(1.0, 1.0), 2);
  EXPECT_EQ(deposit_reach_gap(0.6, 2.0), 1) << "a voxel up is a later layer";
}

// A tall wall beside a low pad: depositing the pad from above, the nozzle body (radius 10,
// from 5 above the bead) reaches over the wall when the wall stands within the square
// inscribed in the body's circle (7 voxels), and does not when it stands farther.
VoxelProblem wall_and_pad(double wall_to) {
  const Solid wall = make_box(kUnit, {{0, 0, 0}, {wall_to, 1, 20}}), pad = make_box(kUnit, {{10, 0, 0}, {14, 1, 2}});
  return make_problem({{"wall", Mode::Additive, false, 1.0, wall}, {"pad", Mode::Additive, false, 1.0, pad}}, unite(wall, pad),
                      {{0, 0, 0}, {30, 1, 30}});
}

TEST(AtomsInNozzleReach, AreTheAtomsTheBodyMeetsOverTheDeposit) {
  const NozzleReach nozzle{10, 5, 60};
  const VoxelProblem near = wall_and_pad(4);  // the wall's last column, x 3, is 7 from the pad's first
  const int wall = near.atoms.atom_at({1, 0, 5}), pad = near.atoms.atom_at({11, 0, 0});
  const auto reach = atoms_in_nozzle_reach(near.atoms, kFromAbove, nozzle);
  ASSERT_FALSE(reach[std::size_t(pad)].words().empty());
  EXPECT_TRUE(reach[std::size_t(pad)].test(wall));
  EXPECT_TRUE(reach[std::size_t(wall)].words().empty() || !reach[std::size_t(wall)].test(pad))
      << "the pad is lower than the standoff over the wall's foot";

  const VoxelProblem far = wall_and_pad(2);  // x 1: 9 from the pad
  const int far_pad = far.atoms.atom_at({11, 0, 0}), far_wall = far.atoms.atom_at({1, 0, 5});
  const auto far_reach = atoms_in_nozzle_reach(far.atoms, kFromAbove, nozzle);
  EXPECT_TRUE(far_reach[std::size_t(far_pad)].words().empty() || !far_reach[std::size_t(far_pad)].test(far_wall));

  // A body shorter than the domain is tall (20 of 30 voxels) still meets the wall: its top
  // (voxel 19) lies within the body over the pad, from 5 above its foot to 25 above its top.
  const auto short_body = atoms_in_nozzle_reach(near.atoms, kFromAbove, {10, 5, 20});
  ASSERT_FALSE(short_body[std::size_t(pad)].words().empty());
  EXPECT_TRUE(short_body[std::size_t(pad)].test(wall));
  // A body 3 long ends 9 above the pad's top: the wall's top stands above it, and the
  // relation, which knows only each atom's highest voxel near a column, does not count it
  // (never more than the nozzle meets).
  const auto three_long = atoms_in_nozzle_reach(near.atoms, kFromAbove, {10, 5, 3});
  EXPECT_TRUE(three_long[std::size_t(pad)].words().empty() || !three_long[std::size_t(pad)].test(wall));
}

// Random decompositions of a small domain, seen from a few approaches, against the
// definitions read literally, voxel pair by voxel pair.
struct ColumnView {
  AxisDirection approach;
  IndexBox d;
  // (u, v) across the column, t along it from the far side (0: the domain's lowest layer).
  std::array<int, 3> of(Index3 p) const {
    const int c[3] = {p.x, p.y, p.z}, lo[3] = {d.lo.x, d.lo.y, d.lo.z}, hi[3] = {d.hi.x, d.hi.y, d.hi.z};
    const int axis = int(approach.axis), ua = (axis + 1) % 3, va = (axis + 2) % 3;
    return {c[ua], c[va], approach.sign > 0 ? c[axis] - lo[axis] : hi[axis] - 1 - c[axis]};
  }
};

VoxelProblem random_boxes(std::mt19937& rng, const IndexBox& domain) {
  std::vector<VoxelPrimitive> prims;
  Solid design(kUnit, domain);
  auto coord = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
  for (int i = 0; i < 5; ++i) {
    Index3 a{coord(0, domain.hi.x - 1), coord(0, domain.hi.y - 1), coord(0, domain.hi.z - 1)};
    Index3 b{coord(0, domain.hi.x - 1), coord(0, domain.hi.y - 1), coord(0, domain.hi.z - 1)};
    const Solid box = make_box(kUnit, {{double(std::min(a.x, b.x)), double(std::min(a.y, b.y)), double(std::min(a.z, b.z))},
                                       {double(std::max(a.x, b.x) + 1), double(std::max(a.y, b.y) + 1),
                                        double(std::max(a.z, b.z) + 1)}});
    prims.push_back({"P" + std::to_string(i + 1), Mode::Additive, false, 1.0, box});
    if (i < 2) design = unite(design, box);
  }
  return make_problem(prims, design, domain);
}

TEST(AtomsInNozzleReach, AgreesWithTheDefinitionVoxelPairByVoxelPairOnRandomDecompositions) {
  std::mt19937 rng(7);
  const IndexBox domain{{0, 0, 0}, {14, 12, 10}};
  for (int round = 0; round < 12; ++round) {
    const VoxelProblem vp = random_boxes(rng, domain);
    const AxisDirection approach = std::array{kFromAbove, kFromBelow, AxisDirection{Axis::X, -1},
                                              AxisDirection{Axis::Y, +1}}[std::size_t(round % 4)];
    const NozzleReach nozzle{2.0 + round % 5, 1 + round % 3, 40};
    const ColumnView view{approach, domain};
    const int half = int(std::floor(nozzle.radius / std::sqrt(2.0) + 1e-9));
    const auto reach = atoms_in_nozzle_reach(vp.atoms, approach, nozzle);
    const int n = vp.atoms.atom_count();
    std::vector<std::vector<bool>> expected(std::size_t(n), std::vector<bool>(std::size_t(n), false));
    // `other` meets the body over `a` when a voxel of `a` lies within the body's square
    // over a voxel of `other`, at least the standoff above it.
    std::vector<std::pair<int, std::array<int, 3>>> voxels;
    for (int z = domain.lo.z; z < domain.hi.z; ++z)
      for (int y = domain.lo.y; y < domain.hi.y; ++y)
        for (int x = domain.lo.x; x < domain.hi.x; ++x) voxels.push_back({vp.atoms.atom_at({x, y, z}), view.of({x, y, z})});
    for (const auto& [other, p] : voxels)
      for (const auto& [a, q] : voxels)
        if (a != other && std::abs(q[0] - p[0]) <= half && std::abs(q[1] - p[1]) <= half && q[2] >= p[2] + nozzle.standoff)
          expected[std::size_t(other)][std::size_t(a)] = true;
    for (int o = 0; o < n; ++o)
      for (int a = 0; a < n; ++a) {
        const AtomSet& s = reach[std::size_t(o)];
        EXPECT_EQ(!s.words().empty() && s.test(a), expected[std::size_t(o)][std::size_t(a)])
            << "round " << round << ": atom " << a << " over atom " << o;
      }
  }
}

TEST(DepositFooting, AgreesWithTheDefinitionOnRandomDecompositions) {
  std::mt19937 rng(11);
  const IndexBox domain{{0, 0, 0}, {14, 12, 10}};
  for (int round = 0; round < 12; ++round) {
    const VoxelProblem vp = random_boxes(rng, domain);
    const AxisDirection approach = std::array{kFromAbove, kFromBelow, AxisDirection{Axis::X, +1},
                                              AxisDirection{Axis::Y, -1}}[std::size_t(round % 4)];
    const ColumnView view{approach, domain};
    const Solid region = unite(make_box(kUnit, {{3, 2, 4}, {9, 8, 7}}), make_box(kUnit, {{8, 5, 2}, {12, 11, 5}}));
    const int reach = 1 + round % 3;
    const DepositFooting f = deposit_footing(vp.atoms, region, approach, reach);
    const int n = vp.atoms.atom_count();
    int first = INT32_MAX;
    region.for_each_voxel([&](Index3 p) { first = std::min(first, view.of(p)[2]); });
    std::vector<DepositFooting::Kind> kind(std::size_t(n), DepositFooting::None);
    std::vector<std::vector<bool>> carriers(std::size_t(n), std::vector<bool>(std::size_t(n), false));
    region.for_each_voxel([&](Index3 p) {
      const auto pv = view.of(p);
      if (pv[2] != first) return;
      const int b = vp.atoms.atom_at(p);
      if (first == 0) {
        kind[std::size_t(b)] = DepositFooting::OnPlate;
        return;
      }
      if (kind[std::size_t(b)] != DepositFooting::OnPlate) kind[std::size_t(b)] = DepositFooting::NeedsCarrier;
      for (int z = domain.lo.z; z < domain.hi.z; ++z)
        for (int y = domain.lo.y; y < domain.hi.y; ++y)
          for (int x = domain.lo.x; x < domain.hi.x; ++x) {
            const auto q = view.of({x, y, z});
            const int a = vp.atoms.atom_at({x, y, z});
            if (a != b && q[2] <= first && q[2] >= first - 2 && std::abs(q[0] - pv[0]) <= reach &&
                std::abs(q[1] - pv[1]) <= reach)
              carriers[std::size_t(b)][std::size_t(a)] = true;
          }
    });
    for (int b = 0; b < n; ++b) {
      ASSERT_EQ(f.kind[std::size_t(b)], kind[std::size_t(b)]) << "round " << round << ", atom " << b;
      if (kind[std::size_t(b)] != DepositFooting::NeedsCarrier) continue;
      for (int a = 0; a < n; ++a)
        EXPECT_EQ(f.carriers[std::size_t(b)].test(a), carriers[std::size_t(b)][std::size_t(a)])
            << "round " << round << ": atom " << a << " under atom " << b;
    }
  }
}

// A block deposited over a raw stock: its first layer (z = 6) is carried by the stock
// when the stock reaches up to it, and by nothing when a gap of 4 voxels lies between.
// As the plan's first action the block would stand on the build plate; after the stock,
// the plate is not there.
VoxelProblem block_over_stock(double stock_top) {
  const Solid stock = make_box(kUnit, {{0, 0, 0}, {20, 1, stock_top}}), block = make_box(kUnit, {{5, 0, 6}, {15, 1, 10}});
  VoxelProblem vp = make_problem({{"stock", Mode::Additive, true, 0.0, stock}, {"block", Mode::Additive, false, 1.0, block}},
                                 unite(stock, block), {{0, 0, 0}, {20, 1, 12}});
  vp.problem.primitives[1].footing = std::make_shared<const DepositFooting>(deposit_footing(vp.atoms, block, kFromAbove, 2));
  return vp;
}

TEST(DepositFooting, IsTheAtomsNearUnderTheFirstLayer) {
  const VoxelProblem touching = block_over_stock(6), apart = block_over_stock(2);
  for (const VoxelProblem* vp : {&touching, &apart}) {
    const DepositFooting& f = *vp->problem.primitives[1].footing;
    const int block = vp->atoms.atom_at({10, 0, 6}), stock = vp->atoms.atom_at({10, 0, 0});
    ASSERT_EQ(f.kind[std::size_t(block)], DepositFooting::NeedsCarrier);
    EXPECT_EQ(f.kind[std::size_t(stock)], DepositFooting::None) << "not in the block's first layer";
    EXPECT_EQ(f.carriers[std::size_t(block)].test(stock), vp == &touching);
  }
  // A first layer on the domain's lowest layer stands on the machine's plate.
  const DepositFooting on_plate = deposit_footing(touching.atoms, touching.primitives[0].region, kFromAbove, 2);
  EXPECT_EQ(on_plate.kind[std::size_t(touching.atoms.atom_at({10, 0, 0}))], DepositFooting::OnPlate);
}

TEST(DepositFooting, ABlockWithNothingUnderItIsNotDepositedAfterTheStock) {
  EXPECT_EQ(find_plans(block_over_stock(6).problem, {5}).size(), 1u) << "the stock carries the block";
  const VoxelProblem apart = block_over_stock(2);
  EXPECT_TRUE(find_plans(apart.problem, {5}).empty()) << "the block would be laid over air";
  EXPECT_TRUE(enumerate_plans(apart.problem).empty());
  VoxelProblem blind = apart;
  blind.problem.primitives[1].footing.reset();
  EXPECT_EQ(find_plans(blind.problem, {5}).size(), 1u);
}

TEST(DepositReach, BothFromAboveOnlyTheLowerPartFirst) {
  const VoxelProblem vp = column(kFromAbove, kFromAbove);
  const auto plans = find_plans(vp.problem, {5});
  ASSERT_EQ(plans.size(), 1u) << "the upper part first would leave the lower under it";
  EXPECT_EQ(expression(vp.problem, plans[0]), "(lower \u222A upper)");
  EXPECT_EQ(enumerate_plans(vp.problem).size(), 1u);
  const Reachability reach = explore_reachable(vp.problem);
  EXPECT_TRUE(reach.goal);
  EXPECT_DOUBLE_EQ(reach.wrong_volume, 0);
}

TEST(DepositReach, FromOppositeSidesNoOrderMakesTheColumnAndExplorationProvesIt) {
  const VoxelProblem vp = column(kFromAbove, kFromBelow);
  EXPECT_TRUE(find_plans(vp.problem, {5}).empty());
  EXPECT_TRUE(enumerate_plans(vp.problem).empty());
  const Reachability reach = explore_reachable(vp.problem);
  EXPECT_TRUE(reach.complete);
  EXPECT_FALSE(reach.goal);
  EXPECT_EQ(reach.states, 2) << "each part alone";
  EXPECT_DOUBLE_EQ(reach.wrong_volume, 4.0 * 4) << "the nearest lacks 4 of the 10 layers";

  // Without the relation both orders make it: the search needs it to see the deadlock.
  VoxelProblem blind = vp;
  for (PrimitiveSpec& p : blind.problem.primitives) p.blocked_by.reset();
  EXPECT_EQ(find_plans(blind.problem, {5}).size(), 2u);
  EXPECT_TRUE(explore_reachable(blind.problem).goal);
}

TEST(DepositReach, ExplorationStopsAtItsStateLimitUndecided) {
  const VoxelProblem vp = column(kFromAbove, kFromBelow);
  const Reachability reach = explore_reachable(vp.problem, 1);
  EXPECT_FALSE(reach.complete);
  EXPECT_FALSE(reach.goal);
}

}  // namespace
}  // namespace hybridctl::planner
