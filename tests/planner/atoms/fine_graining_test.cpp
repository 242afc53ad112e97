// Iterative fine-graining (planner/atoms/fine_graining.hpp, the paper's section 8): an atom that
// straddles the design is split by a capability's primitive cut to the neighbourhood of
// the part it should make, and the part becomes manufacturable; where no such cut
// separates the atom's parts, it is reported with the capabilities tried.

#include <gtest/gtest.h>

#include "config/machine_loader.hpp"
#include "planner/atoms/check.hpp"
#include "planner/atoms/fine_graining.hpp"
#include "../planner_fixtures.hpp"

namespace hybridctl::planner {
namespace {

using geometry::Index3;
using geometry::IndexBox;
using geometry::Solid;

const geometry::Lattice kMm{1.0, {0, 0, 0}};
constexpr double kTolerance = 0.5;

Solid box(Index3 lo, Index3 hi) { return Solid::filled(kMm, {lo, hi}); }

config::Machine hybrid_3axis() { return config::load_machine(HYBRIDCTL_SOURCE_DIR "/examples/machines/hybrid-3axis.yaml"); }

Primitive primitive(std::string name, PrimitiveKind kind, Mode mode, std::string capability, int tool, Solid region) {
  Primitive p;
  p.name = std::move(name);
  p.label = p.name;
  p.kind = kind;
  p.mode = mode;
  p.capability = std::move(capability);
  p.setup = "top";
  p.tool_number = tool;
  p.cost_per_mm3 = 1;
  p.region = std::move(region);
  return p;
}

struct Planned {
  std::vector<Primitive> primitives;
  AtomDecomposition atoms;
  std::vector<AtomMeasures> measures;
};

Planned decompose(std::vector<Primitive> primitives, const Solid& design, const IndexBox& domain) {
  AtomDecomposition atoms(kMm, domain);
  for (const Primitive& p : primitives) atoms.add_primitive(p.region);
  std::vector<AtomMeasures> measures = measure_atoms(atoms, design, make_tolerance_zone(design, kTolerance), 0);
  return {std::move(primitives), std::move(atoms), std::move(measures)};
}

int violating(const std::vector<AtomMeasures>& measures) {
  return int(std::count_if(measures.begin(), measures.end(),
                           [](const AtomMeasures& m) { return m.atom_class == AtomClass::Violating; }));
}

testing::VoxelProblem voxel_problem(const Planned& p, const Solid& design, const IndexBox& domain) {
  std::vector<testing::VoxelPrimitive> prims;
  for (const Primitive& q : p.primitives) prims.push_back({q.name, q.mode, false, q.cost_per_mm3, q.region});
  return testing::make_problem(std::move(prims), design, domain, kTolerance);
}

// The paper's kind of example: a 10 mm cube, and the head's deposit, which makes it but
// also a spur standing 10 mm away, beyond the tolerance (on a real machine: two places no
// other primitive tells apart). The milling cutter's primitive reaches neither.
struct SpurredDeposit {
  IndexBox domain{{-4, -4, 0}, {30, 14, 16}};
  Solid design = box({0, 0, 0}, {10, 10, 10});
  Solid spur = box({20, 0, 0}, {23, 3, 3});
  std::vector<Primitive> primitives{
      primitive("P1", PrimitiveKind::OAm, Mode::Additive, "ded", 0, unite(design, spur)),
      primitive("P2", PrimitiveKind::SmMax, Mode::Subtractive, "T1", 1, box({-4, -4, 12}, {30, 14, 16}))};
};

TEST(FineGraining, AnAtomStickingOutOfTheToleranceIsSplitByADepositCutToTheDesignAndThePartBecomesManufacturable) {
  const config::Machine machine = hybrid_3axis();
  const SpurredDeposit part;
  Planned p = decompose(part.primitives, part.design, part.domain);
  ASSERT_EQ(violating(p.measures), 1);
  EXPECT_FALSE(check_manufacturability(voxel_problem(p, part.design, part.domain).problem, p.measures, kMm).manufacturable());

  const FineGraining fine = fine_grain(machine, part.design, kTolerance, 0, nullptr, p.primitives, p.atoms, p.measures);

  EXPECT_EQ(fine.added, 1);
  EXPECT_EQ(fine.rounds, 1);
  EXPECT_TRUE(fine.unsplit.empty());
  EXPECT_EQ(violating(p.measures), 0);
  ASSERT_EQ(p.primitives.size(), 3u);
  const Primitive& local = p.primitives.back();
  EXPECT_EQ(local.name, "P3");
  EXPECT_EQ(local.kind, PrimitiveKind::OAm);
  EXPECT_NE(local.label.find("around (5.0, 5.0, 5.0)"), std::string::npos) << local.label;
  EXPECT_TRUE(subtract(part.design, local.region).empty()) << "the local deposit makes the whole cube";
  EXPECT_TRUE(intersect(local.region, part.spur).empty()) << "and none of the spur";
  // The atoms were split in place: the same partition as a decomposition from scratch.
  std::vector<const Solid*> regions;
  for (const Primitive& q : p.primitives) regions.push_back(&q.region);
  EXPECT_TRUE(same_partition(p.atoms, AtomDecomposition::recompute(kMm, part.domain, regions)));

  const testing::VoxelProblem vp = voxel_problem(p, part.design, part.domain);
  EXPECT_TRUE(check_manufacturability(vp.problem, p.measures, kMm).manufacturable());
  const std::vector<Plan> plans = find_plans(vp.problem, SearchOptions{1});
  ASSERT_EQ(plans.size(), 1u);
  ASSERT_EQ(plans.front().steps.size(), 1u);
  EXPECT_EQ(plans.front().steps.front().primitive, 2);
  const Solid made = testing::evaluate(vp, plans.front());
  EXPECT_TRUE(subtract(made, part.design).empty() && subtract(part.design, made).empty());
}

TEST(FineGraining, WithoutAMachineCapabilityNothingIsSplit) {
  // The same deposit given as a file: its instrument is unknown, so no neighbourhood.
  const config::Machine machine = hybrid_3axis();
  SpurredDeposit part;
  part.primitives.front().kind = PrimitiveKind::File;
  Planned p = decompose(part.primitives, part.design, part.domain);
  const FineGraining fine = fine_grain(machine, part.design, kTolerance, 0, nullptr, p.primitives, p.atoms, p.measures);
  EXPECT_EQ(fine.added, 0);
  EXPECT_EQ(p.primitives.size(), 2u);
  ASSERT_EQ(fine.unsplit.size(), 1u);
  EXPECT_NE(fine.unsplit.front().why.find("fine-graining tried nothing"), std::string::npos) << fine.unsplit.front().why;
}

TEST(FineGraining, AnOverfillTouchingTheDesignCannotBeSplitAndTheAtomIsReportedWithTheCapabilitiesTried) {
  // The deposit overfills the cube's +X face by 2 mm, and no cutter reaches there: the
  // overfill lies within a bead of the cube, so no cut of the deposit leaves it out.
  const config::Machine machine = hybrid_3axis();
  const IndexBox domain{{-4, -4, 0}, {20, 14, 16}};
  const Solid design = box({0, 0, 0}, {10, 10, 10});
  std::vector<Primitive> prims{
      primitive("P1", PrimitiveKind::OAm, Mode::Additive, "ded", 0, box({0, 0, 0}, {12, 10, 10})),
      primitive("P2", PrimitiveKind::SmMax, Mode::Subtractive, "T1", 1, box({-4, -4, 12}, {20, 14, 16}))};
  Planned p = decompose(prims, design, domain);
  ASSERT_EQ(violating(p.measures), 1);
  const FineGraining fine = fine_grain(machine, design, kTolerance, 0, nullptr, p.primitives, p.atoms, p.measures);
  EXPECT_EQ(fine.added, 0);
  EXPECT_EQ(fine.rounds, 0);
  ASSERT_EQ(fine.unsplit.size(), 1u);
  const std::string& why = fine.unsplit.front().why;
  EXPECT_NE(why.find("1 capability (ded in top)"), std::string::npos) << why;
  EXPECT_NE(why.find("no tool removes any of the"), std::string::npos) << why;
}

}  // namespace
}  // namespace hybridctl::planner
