// The rule of faces left as deposited (planner/pipeline/deposited_faces.hpp): a deposit
// whose head lays material coarser than the tolerance, or an overfill laid with a
// machining allowance beyond it, may leave none of its faces as it laid them, and one an
// executed candidate showed beyond the tolerance at a place may not leave that face
// again; a removal after it that clears material beside the face (an overfill) finishes it,
// and where the face stood out, one whose region holds the air beside it.
//
// The problem: a block 4 x 4 x 3 mm on a 1 mm grid, deposited near-net (P1) or with a
// millimetre of overfill round it (P2, an O-AM), a removal that holds all the air round it
// (P3), and one that holds only air far off (P4).

#include <gtest/gtest.h>

#include "planner/atoms/tolerance_zone.hpp"
#include "planner/pipeline/deposited_faces.hpp"

namespace hybridctl::planner {
namespace {

const geometry::Lattice kLattice{1.0, {0, 0, 0}};
const geometry::IndexBox kDomain{{0, 0, 0}, {14, 8, 8}};

geometry::Solid box(geometry::Index3 lo, geometry::Index3 hi) {
  geometry::Solid s(kLattice, kDomain);
  for (int z = lo.z; z < hi.z; ++z)
    for (int y = lo.y; y < hi.y; ++y)
      for (int x = lo.x; x < hi.x; ++x) s.set({x, y, z});
  return s;
}

struct Block {
  geometry::Solid design = box({1, 1, 0}, {5, 5, 3});
  geometry::Solid overfilled = box({0, 0, 0}, {6, 6, 4});
  geometry::Solid air_round = geometry::subtract(box({0, 0, 0}, {14, 8, 8}), design);
  geometry::Solid air_far = box({11, 0, 0}, {14, 8, 8});
  AtomDecomposition atoms = AtomDecomposition::recompute(kLattice, kDomain, {&design, &overfilled, &air_round, &air_far});
  std::vector<AtomMeasures> measures = measure_atoms(atoms, design, make_tolerance_zone(design, 0.5), 0);
  std::vector<Primitive> primitives;
  PlanningProblem problem;

  Block() {
    const std::vector<std::pair<Mode, std::string>> kinds = {
        {Mode::Additive, "powder"}, {Mode::Additive, "powder"}, {Mode::Subtractive, "T1"}, {Mode::Subtractive, "T1"}};
    for (std::size_t i = 0; i < kinds.size(); ++i) {
      Primitive p;
      p.name = "P" + std::to_string(i + 1);
      p.mode = kinds[i].first;
      p.capability = kinds[i].second;
      if (i == 1) p.kind = PrimitiveKind::OAm;
      primitives.push_back(p);
      PrimitiveSpec s;
      s.name = p.name;
      s.mode = p.mode;
      s.tool = p.capability;
      s.atoms = AtomSet(atoms.atom_count());
      for (int a = 0; a < atoms.atom_count(); ++a)
        if (atoms.code(a).test(int(i))) s.atoms.set(a);
      problem.primitives.push_back(s);
    }
    for (const AtomMeasures& m : measures)
      problem.atoms.push_back({m.volume, m.atom_class == AtomClass::MustIn, m.atom_class == AtomClass::MustOut});
  }

  FaceRule rule(double head_accuracy, double tolerance, double allowance = 0.5) const {
    config::Machine machine;
    config::AdditiveHead head;
    head.name = "powder";
    head.accuracy = head_accuracy;
    head.machining_allowance = allowance;
    machine.heads.push_back(head);
    return make_face_rule(machine, primitives, problem, atoms, measures, tolerance);
  }
};

Plan plan_of(std::initializer_list<int> primitives) {
  Plan plan;
  for (const int p : primitives) plan.steps.push_back({p, 0, 0});
  return plan;
}

TEST(DepositedFaces, AHeadCoarserThanTheToleranceLeavesNoFaceAsItLaidIt) {
  const Block b;
  const FaceRule rule = b.rule(1.0, 0.5);
  const std::optional<FaceLeft> left = face_left_as_deposited(b.problem, rule, plan_of({0}));
  ASSERT_TRUE(left.has_value());
  EXPECT_EQ(left->step, 0u);
  const std::string told = describe_face_left(b.problem, rule, b.measures, plan_of({0}), *left);
  EXPECT_NE(told.find("P1 (action 1) leaves the face around"), std::string::npos) << told;
  EXPECT_NE(told.find("lays material within 1 mm of its beads, coarser than the tolerance 0.5 mm"), std::string::npos)
      << told;
  // A removal after the overfilled deposit clears the overfill beside every face and
  // finishes them; after the near-net one it runs in air and finishes none; one that holds
  // only air far off finishes none either way.
  EXPECT_FALSE(face_left_as_deposited(b.problem, rule, plan_of({1, 2})).has_value());
  EXPECT_TRUE(face_left_as_deposited(b.problem, rule, plan_of({1})).has_value());
  EXPECT_TRUE(face_left_as_deposited(b.problem, rule, plan_of({0, 2})).has_value());
  EXPECT_TRUE(face_left_as_deposited(b.problem, rule, plan_of({1, 3})).has_value());
}

TEST(DepositedFaces, AHeadWithinTheToleranceMayLeaveItsFacesAsLaid) {
  const Block b;
  const FaceRule rule = b.rule(0.25, 0.5);
  EXPECT_FALSE(face_left_as_deposited(b.problem, rule, plan_of({0})).has_value());
  EXPECT_TRUE(rule.why[0].empty());
}

TEST(DepositedFaces, ADepositLaidWithAnAllowanceBeyondTheToleranceLeavesNoFaceAsLaid) {
  const Block b;
  const FaceRule rule = b.rule(0.25, 0.5, 1.0);
  EXPECT_TRUE(rule.why[0].empty());  // near-net: its faces may stay
  EXPECT_FALSE(face_left_as_deposited(b.problem, rule, plan_of({0})).has_value());
  const std::optional<FaceLeft> left = face_left_as_deposited(b.problem, rule, plan_of({1}));
  ASSERT_TRUE(left.has_value());
  EXPECT_NE(describe_face_left(b.problem, rule, b.measures, plan_of({1}), *left)
                .find("it is laid with the machining allowance of powder, 1 mm beyond the design, for a removal to finish"),
            std::string::npos);
  EXPECT_FALSE(face_left_as_deposited(b.problem, rule, plan_of({1, 2})).has_value());
  EXPECT_TRUE(face_left_as_deposited(b.problem, rule, plan_of({1, 3})).has_value());
  // An allowance within the tolerance may stay as laid.
  EXPECT_FALSE(face_left_as_deposited(b.problem, b.rule(0.25, 0.5, 0.4), plan_of({1})).has_value());
}

TEST(DepositedFaces, AFaceAnExecutedCandidateLeftOutIsNotLeftAgain) {
  const Block b;
  FaceRule rule = b.rule(0.25, 0.5);
  // The block's top, 0.6 mm out as deposited at its middle.
  const DepositedFace top{0, {3.0, 3.0, 3.1}, 0.6};
  EXPECT_TRUE(learn_face(rule, b.problem, b.atoms, b.measures, top));
  EXPECT_FALSE(learn_face(rule, b.problem, b.atoms, b.measures, top));  // nothing new
  ASSERT_EQ(rule.learned.size(), 1u);
  const std::optional<FaceLeft> left = face_left_as_deposited(b.problem, rule, plan_of({0}));
  ASSERT_TRUE(left.has_value());
  EXPECT_NE(describe_face_left(b.problem, rule, b.measures, plan_of({0}), *left)
                .find("an executed candidate left it 0.600 mm off the STL there as deposited"),
            std::string::npos);
  EXPECT_FALSE(face_left_as_deposited(b.problem, rule, plan_of({1, 2})).has_value());
  EXPECT_FALSE(face_left_as_deposited(b.problem, rule, plan_of({1})).has_value());  // another deposit's face
  // It stood out: a removal after the near-net deposit whose region holds the air there
  // meets the bead's overfill in the material really present and finishes it; one that
  // holds only air far off does not.
  EXPECT_FALSE(face_left_as_deposited(b.problem, rule, plan_of({0, 2})).has_value());
  EXPECT_TRUE(face_left_as_deposited(b.problem, rule, plan_of({0, 3})).has_value());
  // A removal is never held to it, and a place off every face teaches nothing.
  EXPECT_FALSE(learn_face(rule, b.problem, b.atoms, b.measures, {2, {3.0, 3.0, 3.1}, 0.6}));
  EXPECT_FALSE(learn_face(rule, b.problem, b.atoms, b.measures, {0, {12.5, 4.0, 6.0}, 0.6}));
}

// A face that fell short of the design as deposited is not finished by cutting air beside
// it: only a removal that clears material laid beyond it (the overfill's) makes it.
TEST(DepositedFaces, AFaceAnExecutedCandidateLeftShortIsFinishedOnlyFromAnOverfill) {
  const Block b;
  FaceRule rule = b.rule(0.25, 0.5);
  DepositedFace side{0, {5.1, 3.0, 1.5}, 0.7};
  side.excess = false;
  EXPECT_TRUE(learn_face(rule, b.problem, b.atoms, b.measures, side));
  EXPECT_TRUE(face_left_as_deposited(b.problem, rule, plan_of({0})).has_value());
  EXPECT_TRUE(face_left_as_deposited(b.problem, rule, plan_of({0, 2})).has_value());
  EXPECT_FALSE(face_left_as_deposited(b.problem, rule, plan_of({1, 2})).has_value());
}

}  // namespace
}  // namespace hybridctl::planner
