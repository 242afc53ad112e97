// The plan in memory is the plan on disk: to_plan_file(result) equals what
// read_plan_file gives back from the directory write_plan_directory(result) wrote, down to
// where each solid stores its voxels (the simulation's domain is a stock's storage box).
// The flanged hub on the bundled hybrid machine, at a coarse 1 mm voxel.

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>

#include "config/machine_loader.hpp"
#include "geometry/mesh.hpp"
#include "plan/plan_file.hpp"
#include "plan/plan_machine.hpp"
#include "planner/pipeline/plan_report.hpp"

namespace hybridctl::planner {
namespace {

namespace fs = std::filesystem;

void expect_same_storage(const geometry::Solid& memory, const geometry::Solid& disk, const std::string& what) {
  EXPECT_EQ(memory, disk) << what;
  if (!disk.empty()) {
    EXPECT_EQ(memory.storage_box(), disk.storage_box()) << what;
  }
}

TEST(PlanInMemory, EqualsThePlanReadBackFromItsDirectory) {
  const std::string machine_text = config::read_machine_text(HYBRIDCTL_SOURCE_DIR "/examples/machines/hybrid-3axis.yaml");
  const config::Machine machine = config::parse_machine(machine_text, "hybrid-3axis.yaml");
  const geometry::TriangleMesh part = geometry::read_stl(HYBRIDCTL_SOURCE_DIR "/examples/parts/flanged-hub.stl");
  PlanningOptions options;
  options.voxel_size = 1.0;
  options.top_k = 3;
  const PlanningResult result = plan_part(part, "flanged-hub.stl", machine, options);
  ASSERT_FALSE(result.plans.empty());
  const ReportSources sources{HYBRIDCTL_SOURCE_DIR "/examples/parts/flanged-hub.stl", "hybrid-3axis.yaml", machine.name, machine_text};
  const fs::path dir = fs::temp_directory_path() / ("hybridctl-plan-in-memory-" + std::to_string(::getpid()));
  write_plan_directory(result, sources, dir);
  const plan::PlanFile disk = plan::read_plan_file(dir);
  fs::remove_all(dir);

  const plan::PlanFile memory = to_plan_file(result, sources, dir);
  EXPECT_TRUE(memory == disk);
  EXPECT_EQ(memory.directory, disk.directory);
  EXPECT_EQ(memory.machine_yaml, machine_text);
  EXPECT_EQ(disk.machine_hash, plan::machine_text_hash(machine_text));
  EXPECT_EQ(memory.part, disk.part);
  EXPECT_EQ(memory.lattice, disk.lattice);
  EXPECT_EQ(memory.domain, disk.domain);
  EXPECT_EQ(memory.tolerance, disk.tolerance);
  expect_same_storage(memory.design, disk.design, "design");
  ASSERT_EQ(memory.primitives.size(), disk.primitives.size());
  for (std::size_t i = 0; i < disk.primitives.size(); ++i) {
    EXPECT_TRUE(memory.primitives[i] == disk.primitives[i]) << disk.primitives[i].name;
    expect_same_storage(memory.primitives[i].region, disk.primitives[i].region, disk.primitives[i].name);
  }
  ASSERT_EQ(memory.plans.size(), disk.plans.size());
  for (std::size_t k = 0; k < disk.plans.size(); ++k) {
    EXPECT_TRUE(memory.plans[k] == disk.plans[k]) << disk.plans[k].expression;
    const auto from_memory = plan_states(memory, memory.plans[k]), from_disk = plan_states(disk, disk.plans[k]);
    ASSERT_EQ(from_memory.size(), from_disk.size());
    for (std::size_t s = 0; s < from_disk.size(); ++s)
      expect_same_storage(from_memory[s], from_disk[s], disk.plans[k].expression + " state " + std::to_string(s));
  }
}

// PlanningOptions::validate turns candidates down: the planner keeps them with their
// reasons, goes on to the next, and plan.json's `rejected` reads back as it was written.
TEST(PlanInMemory, RejectedCandidatesAreKeptWithTheirReasonsAndReadBack) {
  const std::string machine_text = config::read_machine_text(HYBRIDCTL_SOURCE_DIR "/examples/machines/hybrid-3axis.yaml");
  const config::Machine machine = config::parse_machine(machine_text, "hybrid-3axis.yaml");
  const geometry::TriangleMesh part = geometry::read_stl(HYBRIDCTL_SOURCE_DIR "/examples/parts/flanged-hub.stl");
  PlanningOptions options;
  options.voxel_size = 1.0;
  options.top_k = 2;
  const PlanningResult unvalidated = plan_part(part, "flanged-hub.stl", machine, options);
  ASSERT_EQ(unvalidated.plans.size(), 2u);
  int offered = 0;
  options.validate = [&offered](const PlanningResult&, const Plan&) {
    // The two cheapest candidates fail, located and not.
    ++offered;
    if (offered == 1) return std::vector<plan::RejectionReason>{{"gouge", 2, 6112, "a cut into the core", geometry::Vec3{1.5, 2.25, 3}}};
    if (offered == 2) return std::vector<plan::RejectionReason>{{"missing_material", 0, 0, "the fin is missing", std::nullopt}};
    return std::vector<plan::RejectionReason>{};
  };
  const PlanningResult result = plan_part(part, "flanged-hub.stl", machine, options);
  EXPECT_TRUE(result.validated);
  ASSERT_EQ(result.rejected.size(), 2u);
  ASSERT_EQ(result.plans.size(), 2u);
  EXPECT_EQ(expression(result.problem, result.rejected[0].plan), expression(unvalidated.problem, unvalidated.plans[0]));
  EXPECT_EQ(expression(result.problem, result.rejected[1].plan), expression(unvalidated.problem, unvalidated.plans[1]));
  EXPECT_GE(result.plans[0].cost, unvalidated.plans[1].cost);
  EXPECT_EQ(offered, 4);

  const ReportSources sources{HYBRIDCTL_SOURCE_DIR "/examples/parts/flanged-hub.stl", "hybrid-3axis.yaml", machine.name, machine_text};
  const fs::path dir = fs::temp_directory_path() / ("hybridctl-plan-rejected-" + std::to_string(::getpid()));
  write_plan_directory(result, sources, dir);
  const plan::PlanFile disk = plan::read_plan_file(dir);
  fs::remove_all(dir);
  const plan::PlanFile memory = to_plan_file(result, sources, dir);
  EXPECT_TRUE(memory == disk);
  ASSERT_EQ(disk.rejected.size(), 2u);
  EXPECT_EQ(disk.rejected[0].reasons, result.rejected[0].reasons);
  EXPECT_EQ(disk.rejected[1].reasons, result.rejected[1].reasons);
  EXPECT_EQ(disk.rejected[0].actions.size(), result.rejected[0].plan.steps.size());
  const std::string summary = plan_summary(result, sources);
  EXPECT_NE(summary.find("2 candidates rejected (first reasons: gouge 1, missing_material 1)"), std::string::npos) << summary;
}

}  // namespace
}  // namespace hybridctl::planner
