// What executing a candidate shows about the symbolic model (planner/pipeline/shortfall.hpp): an
// atom the plan needs that is not as planned after the action that last changed it is
// charged to that action's primitive; planning takes it out of the primitive and searches
// again, so that it offers validation plans that do not count on it.

#include <gtest/gtest.h>

#include <algorithm>

#include "config/machine_loader.hpp"
#include "geometry/mesh.hpp"
#include "planner/pipeline/planning.hpp"
#include "planner/search/steps.hpp"
#include "planner/pipeline/shortfall.hpp"

namespace hybridctl::planner {
namespace {

using geometry::Index3;
using geometry::Solid;

const geometry::Lattice kMm{1.0, {0, 0, 0}};
const geometry::IndexBox kRow{{0, 0, 0}, {4, 1, 1}};  // four voxels along X

Solid voxels(int x0, int x1) { return Solid::filled(kMm, {{x0, 0, 0}, {x1, 1, 1}}); }

// Primitives along a row of voxels (P0, P1, ... in the order given; `stock` the raw
// stock's index) and a design of the first `design` voxels: an atom inside it is must-in,
// one outside must-out, its volume its voxels'.
struct Row {
  AtomDecomposition atoms = AtomDecomposition::recompute(kMm, kRow, {});
  PlanningProblem problem;
  Row(int length, const std::vector<std::pair<Solid, Mode>>& primitives, int stock, int design) {
    std::vector<const Solid*> regions;
    for (const auto& [region, mode] : primitives) regions.push_back(&region);
    atoms = AtomDecomposition::recompute(kMm, {{0, 0, 0}, {length, 1, 1}}, regions);
    for (int a = 0; a < atoms.atom_count(); ++a) {
      const Solid voxels_of = atoms.atom_solid(a);
      const bool inside = voxels_of.bounding_box().hi.x <= design;
      problem.atoms.push_back({double(voxels_of.voxel_count()), inside, !inside});
    }
    for (int i = 0; i < int(primitives.size()); ++i) {
      PrimitiveSpec p;
      p.name = "P" + std::to_string(i);
      p.mode = primitives[std::size_t(i)].second;
      p.raw_stock = i == stock;
      p.atoms = AtomSet(atoms.atom_count());
      for (int a = 0; a < atoms.atom_count(); ++a)
        if (atoms.code(a).test(i)) p.atoms.set(a);
      problem.primitives.push_back(std::move(p));
    }
  }
  // A row of four voxels: a deposit of all four (P0), a removal of the last (P1), and a
  // stock of the first (P2). The design is the first three voxels.
  Row() : Row(4, {{voxels(0, 4), Mode::Additive}, {voxels(3, 4), Mode::Subtractive}, {voxels(0, 1), Mode::Additive}}, 2, 3) {}
  int atom_at(int x) const { return atoms.atom_at({x, 0, 0}); }
  Plan plan(std::vector<int> primitives) const {
    Plan plan;
    for (int i : primitives) plan.steps.push_back({i, 0, 0});
    return plan;
  }
};

TEST(Shortfall, ADepositThatLeftLessThanHalfOfAnAtomTheDesignNeedsFellShortOnIt) {
  const Row row;
  // On the stock, deposited all four: the middle two were not built.
  const std::vector<Shortfall> found = find_shortfalls(row.problem, row.atoms, row.plan({2, 0}), 2, voxels(0, 1));
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found[0].primitive, 0);
  EXPECT_EQ(found[0].atom, row.atom_at(1));
  EXPECT_EQ(row.atom_at(1), row.atom_at(2));
  EXPECT_DOUBLE_EQ(found[0].volume, 2.0);
  // Built as planned, or only half an atom short: nothing to learn.
  EXPECT_TRUE(find_shortfalls(row.problem, row.atoms, row.plan({2, 0}), 2, voxels(0, 4)).empty());
  EXPECT_TRUE(find_shortfalls(row.problem, row.atoms, row.plan({2, 0}), 2, voxels(0, 2)).empty());
}

TEST(Shortfall, OnlyTheLastActionExecutedIsChargedAndNeverTheFirst) {
  const Row row;
  // The removal left the last voxel: it fell short on it.
  std::vector<Shortfall> found = find_shortfalls(row.problem, row.atoms, row.plan({0, 1}), 2, voxels(0, 4));
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found[0].primitive, 1);
  EXPECT_EQ(found[0].atom, row.atom_at(3));
  // Judged after the first action only, the last voxel was meant to be there; and the
  // first action is not charged with the middle voxels (it works on the plate).
  EXPECT_TRUE(find_shortfalls(row.problem, row.atoms, row.plan({0, 1}), 1, voxels(0, 1)).empty());
  // The middle voxels missing after the removal: the deposit before it changed them last,
  // and what happened to them since is not known.
  found = find_shortfalls(row.problem, row.atoms, row.plan({2, 0, 1}), 3, voxels(0, 1));
  EXPECT_TRUE(found.empty());
}

TEST(Shortfall, RawStockIsNeverCharged) {
  const Row row;
  // The stock's voxel missing after the stock alone: the plan did not start, no primitive fell short.
  EXPECT_TRUE(find_shortfalls(row.problem, row.atoms, row.plan({2}), 1, Solid(kMm, kRow)).empty());
}

TEST(Shortfall, CoreMissingAfterTheAdditionsIsChargedToTheDepositThatLaidItsAtom) {
  const Row row;
  const Solid missing = Solid::filled(kMm, {{1, 0, 0}, {2, 1, 1}});  // one voxel of the middle atom
  // Half of the middle atom built: too little to tell from the atom alone, but the core
  // missing there is the deposit's, as nothing after it removes.
  const Solid built = geometry::unite(voxels(0, 1), voxels(2, 4));
  EXPECT_TRUE(find_shortfalls(row.problem, row.atoms, row.plan({2, 0}), 2, built).empty());
  std::vector<Shortfall> found = find_missing_core_shortfalls(row.problem, row.atoms, row.plan({2, 0}), 2, missing);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found[0], (Shortfall{0, row.atom_at(1), row.problem.atoms[std::size_t(row.atom_at(1))].volume}));
  // A removal after the deposit may have taken it; the first action works on the plate.
  EXPECT_TRUE(find_missing_core_shortfalls(row.problem, row.atoms, row.plan({2, 0, 1}), 3, missing).empty());
  EXPECT_TRUE(find_missing_core_shortfalls(row.problem, row.atoms, row.plan({0}), 1, missing).empty());
  // The stock's voxel missing: never charged (the deposit did not lay it, the stock did).
  EXPECT_TRUE(find_missing_core_shortfalls(row.problem, row.atoms, row.plan({2, 0}), 2, voxels(0, 1)).empty());
}

TEST(Shortfall, ALayerTheLastActionSkippedChargesTheAtomsMissingWhereTheToolpathSaid) {
  const Row row;
  const Solid built = geometry::unite(voxels(0, 2), voxels(3, 4));  // voxel 2 not laid
  const plan::RejectionReason skipped{"layer_skipped", 2, 0, "layer 3 ... skipped", geometry::Vec3{2.5, 0.5, 0.5}};
  std::vector<Shortfall> found =
      find_skipped_layer_shortfalls(row.problem, row.atoms, row.plan({2, 0}), 2, built, {skipped});
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found[0], (Shortfall{0, row.atom_at(2), row.problem.atoms[std::size_t(row.atom_at(2))].volume}));
  // Another action's skip, another kind of reason, or nothing missing near it: nothing.
  plan::RejectionReason other = skipped;
  other.action = 1;
  EXPECT_TRUE(find_skipped_layer_shortfalls(row.problem, row.atoms, row.plan({2, 0}), 2, built, {other}).empty());
  other = skipped;
  other.kind = "gouge";
  EXPECT_TRUE(find_skipped_layer_shortfalls(row.problem, row.atoms, row.plan({2, 0}), 2, built, {other}).empty());
  EXPECT_TRUE(find_skipped_layer_shortfalls(row.problem, row.atoms, row.plan({2, 0}), 2, voxels(0, 4), {skipped}).empty());
}

// A row of six voxels, the design the first three: a deposit of the design (P0), a removal
// of the last voxel that spares the design (P1), a stock of the first (P2) and a removal of
// the last four that cuts the design (P3). Voxels 3 and 4 are one must-out atom that only
// the cutting removal holds.
Row spill_row() {
  return Row(6,
             {{voxels(0, 3), Mode::Additive},
              {voxels(5, 6), Mode::Subtractive},
              {voxels(0, 1), Mode::Additive},
              {voxels(2, 6), Mode::Subtractive}},
             2, 3);
}

TEST(Shortfall, ADepositThatLeavesMaterialWhereNoRemovalSparingTheDesignReachesSpillsOntoThatAtom) {
  const Row row = spill_row();
  const int beside = row.atom_at(3);
  ASSERT_EQ(row.atom_at(4), beside);
  // Both voxels beside the design filled: the deposit is charged with the whole atom.
  std::vector<Shortfall> found = find_spills(row.problem, row.atoms, row.plan({2, 0}), 2, voxels(0, 5), {});
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found[0], (Shortfall{0, beside, 2.0, true}));
  // Half of it: only where validation says the part is worst.
  EXPECT_TRUE(find_spills(row.problem, row.atoms, row.plan({2, 0}), 2, voxels(0, 4), {}).empty());
  const plan::RejectionReason worst{"excess_material", 0, 0, "as built, ...", geometry::Vec3{3.5, 0.5, 0.5}};
  found = find_spills(row.problem, row.atoms, row.plan({2, 0}), 2, voxels(0, 4), {worst});
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found[0].atom, beside);
  // Material on the last voxel: the sparing removal may clear it; the plan left it, not the deposit.
  const Solid last = geometry::unite(voxels(0, 3), voxels(5, 6));
  EXPECT_TRUE(find_spills(row.problem, row.atoms, row.plan({2, 0}), 2, last, {}).empty());
  // Nothing deposited but the stock: no deposit to charge.
  EXPECT_TRUE(find_spills(row.problem, row.atoms, row.plan({2}), 1, voxels(0, 5), {}).empty());
}

// A spill onto an atom that must stay empty only to keep a gap open, and lies within the
// tolerance zone's hull, is the grid's where the part made is within the tolerance near it
// on the STL (a concave corner's voxels, which a bead laid up to the real faces fills); it
// is the deposit's where exact verification finds excess beyond the tolerance by it, where
// the atom lies beyond the hull, and where nothing was judged on the STL.
TEST(Shortfall, ASpillOntoAGapsVoxelsWithinTheHullIsTheGridsWhereTheStlSaysTheCornerIsWithin) {
  // Three atoms along a row of 1 mm voxels: a gap's within the hull (x = 0..2), a gap's
  // reaching beyond it (x = 2..4), one beyond it and no gap (x = 4..6).
  const Solid a = voxels(0, 2), b = voxels(2, 4);
  const AtomDecomposition atoms = AtomDecomposition::recompute(kMm, {{0, 0, 0}, {6, 1, 1}}, {&a, &b});
  const int corner = atoms.atom_at({0, 0, 0}), reaching = atoms.atom_at({2, 0, 0}), beyond = atoms.atom_at({4, 0, 0});
  std::vector<AtomMeasures> measures(std::size_t(atoms.atom_count()));
  measures[std::size_t(corner)].thin_gap = true;
  measures[std::size_t(reaching)].thin_gap = true;
  measures[std::size_t(reaching)].voxels_beyond_hull = 1;
  measures[std::size_t(beyond)].voxels_beyond_hull = 2;
  const std::vector<Shortfall> spills{
      {0, corner, 2.0, true}, {0, reaching, 2.0, true}, {0, beyond, 2.0, true}, {1, corner, 2.0, false}};
  plan::ExactDeviation exact;
  exact.tolerance = 0.3;
  exact.excess = {0.39, geometry::Vec3{5.5, 0.5, 0.5}, 1, 100, true, false};  // three voxels from the corner's
  EXPECT_EQ(spills_beyond_the_grid(spills, atoms, measures, exact),
            (std::vector<Shortfall>{spills[1], spills[2], spills[3]}));
  // Excess beyond the tolerance within two voxels of the corner's atom: the deposit's.
  exact.excess.at = geometry::Vec3{3.5, 0.5, 0.5};
  EXPECT_EQ(spills_beyond_the_grid(spills, atoms, measures, exact), spills);
  // Excess there but within the tolerance: the grid's.
  exact.excess.mm = 0.25;
  EXPECT_EQ(spills_beyond_the_grid(spills, atoms, measures, exact).size(), 3u);
  // Not judged on the STL: every spill stands.
  EXPECT_EQ(spills_beyond_the_grid(spills, atoms, measures, std::nullopt), spills);
}

// The bundled flanged hub on hybrid-3axis at 1 mm, planned with the test's options (its
// validation hook stands in for execution).
PlanningResult plan_flanged_hub(PlanningOptions options) {
  static const config::Machine machine = config::load_machine(HYBRIDCTL_SOURCE_DIR "/examples/machines/hybrid-3axis.yaml");
  static const geometry::TriangleMesh part = geometry::read_stl(HYBRIDCTL_SOURCE_DIR "/examples/parts/flanged-hub.stl");
  options.voxel_size = 1.0;
  return plan_part(part, "flanged-hub.stl", machine, options);
}

// Planning with a validation that turns the first candidate down, reporting that its last
// action did not do what the plan counts on for one atom: the search stops, the atom is
// taken out of that primitive, and the next search offers only plans that do not count on
// it; the first candidate is not offered again.
TEST(Shortfall, PlanningLearnsFromARejectionAndSearchesAgainWithoutIt) {
  PlanningOptions options;
  options.top_k = 2;
  std::vector<std::vector<int>> offered;
  Shortfall taught;
  options.validate = [&](const PlanningResult& r, const Plan& plan) {
    std::vector<int> sequence;
    for (const PlanStep& s : plan.steps) sequence.push_back(s.primitive);
    offered.push_back(sequence);
    if (offered.size() > 1) return CandidateCheck{};
    // The last action changed some atom the design needs decided: say it did not.
    const int last = plan.steps.back().primitive;
    const PrimitiveSpec& prim = r.problem.primitives[std::size_t(last)];
    const AtomSet region = step_region(r, plan, plan.steps.size() - 1);
    for (int a = 0; a < int(r.problem.atoms.size()); ++a) {
      const AtomSpec& spec = r.problem.atoms[std::size_t(a)];
      const bool needed = prim.mode == Mode::Additive ? spec.must_in : spec.must_out;
      if (region.test(a) && needed && (taught.atom < 0 || spec.volume > r.problem.atoms[std::size_t(taught.atom)].volume))
        taught = {last, a, spec.volume};
    }
    return CandidateCheck{{{"missing_material", 0, 0, "the atom is not there", std::nullopt}}, {taught}};
  };
  const PlanningResult result = plan_flanged_hub(options);
  ASSERT_GE(taught.atom, 0);
  ASSERT_EQ(result.rejected.size(), 1u);
  ASSERT_EQ(result.learned.size(), 1u);
  EXPECT_EQ(result.learned[0], taught);
  EXPECT_EQ(result.search_rounds, 2);
  // Taken out of what the primitive does once the plan has begun; as a first action it still does it.
  const PrimitiveSpec& charged = result.problem.primitives[std::size_t(taught.primitive)];
  ASSERT_FALSE(charged.falls_short.words().empty());
  EXPECT_TRUE(charged.falls_short.test(taught.atom));
  EXPECT_TRUE(charged.atoms.test(taught.atom));
  ASSERT_EQ(result.plans.size(), 2u);
  // Each candidate offered once; every plan kept reaches the design without the primitive
  // doing what it did not do.
  for (std::size_t i = 0; i < offered.size(); ++i)
    EXPECT_EQ(std::count(offered.begin(), offered.end(), offered[i]), 1) << i;
  for (const Plan& plan : result.plans) {
    EXPECT_TRUE(is_goal(result.problem, plan.final_state)) << expression(result.problem, plan);
    AtomSet state(int(result.problem.atoms.size()));
    Plan replayed;
    std::vector<int> sequence;
    for (const PlanStep& s : plan.steps) sequence.push_back(s.primitive);
    ASSERT_TRUE(simulate(result.problem, sequence, replayed));
    EXPECT_EQ(replayed.final_state, plan.final_state);
  }
  EXPECT_NE(learned_text(result).find("falling short of the model on 1 atom"), std::string::npos) << learned_text(result);
}

// A spill is learned the other way round: the atom joins what the deposit lays, wherever
// the plan stands, and every plan the search offers after it ends with that atom cleared.
TEST(Shortfall, PlanningLearnsASpillAsAnAtomTheDepositLaysToo) {
  PlanningOptions options;
  options.top_k = 2;
  Shortfall taught;
  options.validate = [&](const PlanningResult& r, const Plan& plan) {
    if (taught.atom >= 0) return CandidateCheck{};
    // The first plan with a deposit: its last spilled onto the largest must-out atom it
    // does not hold (those before it are turned down with nothing to learn).
    int deposit = -1;
    for (const PlanStep& s : plan.steps)
      if (r.problem.primitives[std::size_t(s.primitive)].mode == Mode::Additive &&
          !r.problem.primitives[std::size_t(s.primitive)].raw_stock)
        deposit = s.primitive;
    if (deposit < 0) return CandidateCheck{{{"missing_material", 0, 0, "not made", std::nullopt}}};
    for (int a = 0; a < int(r.problem.atoms.size()); ++a) {
      const AtomSpec& spec = r.problem.atoms[std::size_t(a)];
      if (spec.must_out && !r.problem.primitives[std::size_t(deposit)].atoms.test(a) &&
          (taught.atom < 0 || spec.volume > r.problem.atoms[std::size_t(taught.atom)].volume))
        taught = {deposit, a, spec.volume, true};
    }
    return CandidateCheck{{{"excess_material", 0, 0, "material outside", std::nullopt}}, {taught}};
  };
  const PlanningResult result = plan_flanged_hub(options);
  ASSERT_GE(taught.atom, 0);
  ASSERT_EQ(result.learned.size(), 1u);
  EXPECT_TRUE(result.learned[0].spill);
  EXPECT_TRUE(result.problem.primitives[std::size_t(taught.primitive)].atoms.test(taught.atom));
  for (const Plan& plan : result.plans) {
    EXPECT_FALSE(plan.final_state.test(taught.atom)) << expression(result.problem, plan);
    EXPECT_TRUE(is_goal(result.problem, plan.final_state)) << expression(result.problem, plan);
  }
  EXPECT_NE(learned_text(result).find("1 primitive spilling onto 1 atom outside them"), std::string::npos)
      << learned_text(result);
  EXPECT_NE(learned_text(result).find("added to them over 2 searches"), std::string::npos) << learned_text(result);
}

// When the proof on the corrected problem replays a plan, that plan is executed before
// another search runs: here validation turns the first two candidates down, each for one
// atom. The second is the proof's replay, and what it showed corrects the problem again
// without a search; the search after it offers a plan that passes.
TEST(Shortfall, TheCorrectedProofsReplayIsExecutedBeforeAnotherSearch) {
  PlanningOptions options;
  options.top_k = 1;
  std::vector<std::vector<int>> offered;
  int searches_when_offered[2] = {0, 0};
  options.validate = [&](const PlanningResult& r, const Plan& plan) {
    std::vector<int> sequence;
    for (const PlanStep& s : plan.steps) sequence.push_back(s.primitive);
    offered.push_back(sequence);
    if (offered.size() > 2) return CandidateCheck{};
    searches_when_offered[offered.size() - 1] = r.search_rounds;
    const int last = plan.steps.back().primitive;
    const PrimitiveSpec& prim = r.problem.primitives[std::size_t(last)];
    const AtomSet region = step_region(r, plan, plan.steps.size() - 1);
    Shortfall taught;
    for (int a = 0; a < int(r.problem.atoms.size()); ++a) {
      const AtomSpec& spec = r.problem.atoms[std::size_t(a)];
      const bool needed = prim.mode == Mode::Additive ? spec.must_in : spec.must_out;
      if (region.test(a) && needed && (taught.atom < 0 || spec.volume > r.problem.atoms[std::size_t(taught.atom)].volume))
        taught = {last, a, spec.volume};
    }
    return CandidateCheck{{{"missing_material", 0, 0, "the atom is not there", std::nullopt}}, {taught}};
  };
  const PlanningResult result = plan_flanged_hub(options);
  ASSERT_EQ(result.rejected.size(), 2u);
  ASSERT_EQ(result.learned.size(), 2u);
  EXPECT_EQ(result.replay_rounds, 1);
  EXPECT_EQ(searches_when_offered[0], 1);
  EXPECT_EQ(searches_when_offered[1], 1);  // no second search before the replay
  EXPECT_EQ(result.search_rounds, 2);
  ASSERT_EQ(result.plans.size(), 1u);
  for (std::size_t i = 0; i < offered.size(); ++i)
    EXPECT_EQ(std::count(offered.begin(), offered.end(), offered[i]), 1) << i;
  EXPECT_NE(learned_text(result).find("over 2 searches and 1 replay of the proof"), std::string::npos)
      << learned_text(result);
}

}  // namespace
}  // namespace hybridctl::planner
