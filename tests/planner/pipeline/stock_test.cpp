// A raw stock given as a file (PlanningOptions::stock_files, `plan --stock`): a worn part to
// repair. Plans start from it, and deposits are cut to what builds on it, not only to what
// builds up from an empty plate.

#include <gtest/gtest.h>

#include "common/error.hpp"
#include "config/machine_loader.hpp"
#include "geometry/mesh.hpp"
#include "geometry/morphology.hpp"
#include "planner/pipeline/planning.hpp"

namespace hybridctl::planner {
namespace {

const std::string kParts = HYBRIDCTL_SOURCE_DIR "/examples/parts/";

PlanningResult plan_hub(std::vector<std::string> stocks, std::int64_t max_expansions = 10'000) {
  const config::Machine machine = config::load_machine(HYBRIDCTL_SOURCE_DIR "/examples/machines/hybrid-3axis.yaml");
  PlanningOptions options;
  options.stock_files = std::move(stocks);
  options.max_expansions = max_expansions;
  return plan_part(geometry::read_stl(kParts + "flanged-hub.stl"), "flanged-hub", machine, options);
}

// The worn copy of the flanged hub has lost 2.5 mm of its flange's top over half of it.
TEST(StockFile, TheWornPartIsTheOnlyStockAndEveryPlanStartsFromIt) {
  const PlanningResult r = plan_hub({kParts + "flanged-hub-worn.stl"});
  ASSERT_FALSE(r.primitives.empty());
  EXPECT_EQ(r.primitives[0].kind, PrimitiveKind::RawStock);
  EXPECT_TRUE(r.primitives[0].from_file);
  for (std::size_t i = 1; i < r.primitives.size(); ++i) EXPECT_NE(r.primitives[i].kind, PrimitiveKind::RawStock) << i;
  ASSERT_FALSE(r.plans.empty()) << r.verdict.summary;
  for (const Plan& plan : r.plans) EXPECT_EQ(plan.steps.front().primitive, 0) << expression(r.problem, plan);
}

TEST(StockFile, ADepositFromAboveBuildsOnTheWornFlangeItCouldNotBuildFromThePlate) {
  const PlanningResult worn = plan_hub({kParts + "flanged-hub-worn.stl"}, 1);
  const PlanningResult plate = plan_hub({}, 1);
  const auto u_am_top = [](const PlanningResult& r) {
    for (const Primitive& p : r.primitives)
      if (p.kind == PrimitiveKind::UAm && p.setup == "top" && p.label.find(" = ") == std::string::npos) return p.region;
    return geometry::Solid();
  };
  const geometry::Solid missing = subtract(worn.design, worn.primitives[0].region);  // the worn wedge
  ASSERT_GT(missing.volume(), 2000.0);
  // From the plate the flange overhangs the hub: none of the wedge builds from +Z.
  EXPECT_LT(intersect(missing, u_am_top(plate)).volume(), 0.5 * missing.volume());
  // On the worn part the flange is there: all of it does.
  EXPECT_EQ(subtract(missing, u_am_top(worn)).volume(), 0.0);
}

// A repair: besides the whole-part deposits, each head's deposits cut to the neighbourhood
// of what the worn part lacks (planner/primitives/repair.hpp), so that the overfill lies
// where the head and the cutters reach, not all over the part.
TEST(StockFile, ARepairOffersDepositsCutToTheNeighbourhoodOfWhatTheWornPartLacks) {
  const PlanningResult worn = plan_hub({kParts + "flanged-hub-worn.stl"}, 1);
  const geometry::Solid missing = subtract(worn.design, worn.primitives[0].region);
  const Primitive* whole = nullptr;
  const Primitive* local = nullptr;
  for (const Primitive& p : worn.primitives) {
    if (p.kind != PrimitiveKind::OAm || p.setup != "top") continue;
    (p.label.find(", near the missing") == std::string::npos ? whole : local) = &p;
  }
  ASSERT_NE(whole, nullptr);
  ASSERT_NE(local, nullptr);
  EXPECT_EQ(subtract(missing, local->region).volume(), 0.0);  // it makes all that is missing
  EXPECT_LT(local->region.volume(), 0.5 * whole->region.volume());
  // Nothing farther from the missing region than the bead's width (1.5 mm) and the tolerance.
  const geometry::Solid near = dilate(missing, geometry::Ball{2.0 + 1e-9}, worn.domain);
  EXPECT_EQ(subtract(local->region, near).volume(), 0.0);
  // Without a stock there is nothing to repair.
  for (const Primitive& p : plan_hub({}, 1).primitives) EXPECT_EQ(p.label.find(", near the missing"), std::string::npos);
}

TEST(StockFile, AStockAwayFromThePartIsRefusedSayingWhere) {
  geometry::TriangleMesh far = geometry::read_stl(kParts + "flanged-hub-worn.stl");
  for (auto& t : far.triangles)
    for (auto& v : t) v.x += 500;
  const std::string path = ::testing::TempDir() + "/far-stock.stl";
  geometry::write_stl(far, path);
  try {
    plan_hub({path}, 1);
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path + ": the stock has no voxel inside the planning domain"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace hybridctl::plan
