// The job report of a real plan directory (the bundled bracket on the bundled machine at a
// coarse voxel, and the same part on a machine with only a mill): one self-contained page
// within its size budget, with every plan's states and toolpaths, the offending atoms of a
// part that cannot be made, and PNG snapshots that show the part; nothing written for bad
// input or a page over budget. (The exact deviation map: report_exact_test.cpp.)

#include <gtest/gtest.h>
#include <png.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <filesystem>
#include <memory>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "common/error.hpp"
#include "config/machine_loader.hpp"
#include "geometry/mesh.hpp"
#include "plan/plan_file.hpp"
#include "plan/plan_machine.hpp"
#include "plan/start_stock.hpp"
#include "planner/pipeline/plan_report.hpp"
#include "geometry/vdb_file.hpp"
#include "planner/pipeline/candidate_execution.hpp"
#include "report/report.hpp"
#include "report/report_as_built.hpp"
#include "report/report_data.hpp"
#include "report/report_exact.hpp"
#include "report/report_mesh.hpp"
#include "validation/execution.hpp"
#include "validation/plan_validator.hpp"
#include "verification/exact_deviation.hpp"
#include "page_reading.hpp"

namespace hybridctl::report {
namespace {

// Plans the bracket into a fresh directory once per machine.
fs::path plan_directory(const std::string& name, const std::string& machine_text) {
  const fs::path& root = test_root();
  const fs::path dir = root / name;
  if (fs::exists(dir / "plan.json")) return dir;
  fs::create_directories(root);
  const config::Machine machine = config::parse_machine(machine_text, name + ".yaml");
  planner::PlanningOptions options;
  options.voxel_size = 2.0;
  options.top_k = 3;
  const auto part = geometry::read_stl(HYBRIDCTL_SOURCE_DIR "/examples/parts/bracket.stl");
  const planner::PlanningResult result = planner::plan_part(part, "bracket.stl", machine, options);
  planner::write_plan_directory(result, {"bracket.stl", name + ".yaml", machine.name, machine_text}, dir);
  return dir;
}

fs::path bracket() {
  return plan_directory("bracket", config::read_machine_text(HYBRIDCTL_SOURCE_DIR "/examples/machines/hybrid-3axis.yaml"));
}

// Only a cutting tool and no stock: nothing can put material down first.
fs::path mill_only() {
  return plan_directory("mill-only",
                        "name: mill-only\n"
                        "envelope:\n"
                        "  X: {travel: [0, 300]}\n  Y: {travel: [0, 300]}\n  Z: {travel: [0, 300]}\n"
                        "tools:\n  - {number: 1, type: flat, diameter: 6}\n"
                        "setups:\n  - {name: top, approach: +Z}\n"
                        "raw_stocks: []\n");
}

TEST(Report, IsOneSelfContainedPageWithEveryPlanItsStatesAndToolpaths) {
  const fs::path dir = bracket();
  ReportRequest request;
  request.plan = dir;
  const ReportResult r = write_report(request);
  EXPECT_EQ(r.page, dir / "report.html");
  const std::string page = slurp(r.page);
  EXPECT_EQ(r.bytes, page.size());
  EXPECT_LT(page.size(), kDefaultSizeBudget);
  // Nothing is fetched: no external script, style, image or font.
  for (const char* fetch : {"src=\"http", "href=\"http", "<link", "@import", "url(http"})
    EXPECT_EQ(page.find(fetch), std::string::npos) << fetch;
  EXPECT_NE(page.find("REVISION=\"111\""), std::string::npos) << "three.js r111 is not inlined";
  EXPECT_NE(page.find("THREE.OrbitControls"), std::string::npos);
  const nlohmann::json data = page_data(page);
  const nlohmann::json plan = nlohmann::json::parse(slurp(dir / "plan.json"));
  ASSERT_EQ(data["plans"].size(), plan["plans"].size());
  ASSERT_EQ(data["primitives"].size(), plan["primitives"].size());
  EXPECT_EQ(r.plans, int(plan["plans"].size()));
  EXPECT_GT(data["design"]["mesh"]["triangles"].get<int>(), 100);
  for (const auto& p : data["primitives"]) EXPECT_LE(p["mesh"]["triangles"].get<std::size_t>(), request.budget.primitive);
  int with_paths = 0;
  for (std::size_t k = 0; k < data["plans"].size(); ++k) {
    const auto& actions = data["plans"][k]["actions"];
    ASSERT_EQ(actions.size(), plan["plans"][k]["actions"].size());
    for (const auto& a : actions) {
      EXPECT_LE(a["state"]["triangles"].get<std::size_t>(), request.budget.state);
      if (a["toolpath"]["makes_gcode"].get<bool>()) {
        ++with_paths;
        EXPECT_GT(a["toolpath"]["cycle_s"].get<double>(), 0);
        EXPECT_GT(a["toolpath"]["segments"].get<int>(), 0);
      }
    }
  }
  EXPECT_GT(with_paths, 0);
  ASSERT_EQ(r.snapshots.size(), 1 + plan["plans"].size());  // the overview, a strip per plan
  EXPECT_EQ(r.snapshots[1], dir / "report-plan-1.png");
  for (const fs::path& png : r.snapshots) EXPECT_GT(drawn_share(png), 0.05) << png << " shows almost nothing";
}

// `plan --report` hands the report the plan it holds in memory instead of reading the
// solids back from the directory: the page is the same, byte for byte.
TEST(Report, FromThePlanInMemoryIsTheReportFromItsDirectory) {
  const std::string text = config::read_machine_text(HYBRIDCTL_SOURCE_DIR "/examples/machines/hybrid-3axis.yaml");
  const config::Machine machine = config::parse_machine(text, "hybrid-3axis.yaml");
  planner::PlanningOptions options;
  options.voxel_size = 2.0;
  options.top_k = 2;
  const auto part = geometry::read_stl(HYBRIDCTL_SOURCE_DIR "/examples/parts/flanged-hub.stl");
  const planner::PlanningResult result = planner::plan_part(part, "flanged-hub.stl", machine, options);
  ASSERT_FALSE(result.plans.empty());
  const fs::path dir = test_root() / "in-memory";
  // The STL's real path: design.stl is copied, and both pages carry the exact maps.
  const planner::ReportSources sources{HYBRIDCTL_SOURCE_DIR "/examples/parts/flanged-hub.stl", "hybrid-3axis.yaml",
                                       machine.name, text};
  planner::write_plan_directory(result, sources, dir);
  const plan::PlanFile in_memory = planner::to_plan_file(result, sources, dir);

  ReportRequest request;
  request.plan = dir;
  request.snapshots = false;
  request.output = dir / "from-directory.html";
  const ReportResult read = write_report(request);
  request.in_memory = &in_memory;
  request.output = dir / "from-memory.html";
  const ReportResult held = write_report(request);
  EXPECT_EQ(held.plans, 2);
  EXPECT_EQ(held.bytes, read.bytes);
  EXPECT_TRUE(slurp(held.page) == slurp(read.page));
  EXPECT_TRUE(page_data(slurp(held.page))["design"]["surface"].contains("mesh"));
}

TEST(Report, ListsEachOffendingAtomOfAPartTheMachineCannotMake) {
  const fs::path dir = mill_only();
  ReportRequest request;
  request.plan = dir / "plan.json";
  request.output = dir / "not-makeable.html";
  const ReportResult r = write_report(request);
  const nlohmann::json data = page_data(slurp(r.page));
  const nlohmann::json plan = nlohmann::json::parse(slurp(dir / "plan.json"));
  EXPECT_FALSE(data["verdict"]["manufacturable"].get<bool>());
  EXPECT_TRUE(data["plans"].empty());
  const auto& violations = data["verdict"]["violations"];
  ASSERT_FALSE(violations.empty());
  ASSERT_EQ(violations.size(), plan["verdict"]["violations"].size());
  for (std::size_t i = 0; i < violations.size(); ++i) {
    EXPECT_EQ(violations[i]["atom"], plan["verdict"]["violations"][i]["atom"]);
    EXPECT_GT(violations[i]["mesh"]["triangles"].get<int>(), 0) << "atom " << violations[i]["atom"] << " has no surface";
  }
  EXPECT_TRUE(fs::exists(dir / "not-makeable-overview.png"));
}

TEST(Report, SplitsWhatARunBuiltAgainstTheDesignAtThePlanningBand) {
  const fs::path dir = bracket();
  const plan::PlanFile file = plan::read_plan_file(dir);
  // A voxel layer too much on the wall's top (within the band: at a tolerance of 0.5 mm on
  // 2 mm voxels the band is a voxel, plan/planning_band.hpp), a block in the air two voxels
  // out (beyond it), and a hole in the design.
  geometry::Solid built = unite(geometry::Solid(file.lattice, file.domain), file.design);
  const geometry::IndexBox box = file.design.bounding_box();
  for (int y = box.lo.y; y < box.hi.y; ++y) built.set_run(y, box.hi.z, box.lo.x, box.lo.x + 5);
  for (int z = box.lo.z; z < box.lo.z + 3; ++z) built.set_run(box.lo.y - 2, z, box.lo.x, box.lo.x + 3);
  const geometry::Index3 inside{box.lo.x + 2, box.lo.y + 5, box.lo.z + 1};
  ASSERT_TRUE(file.design.contains(inside));
  built.set(inside, false);
  geometry::write_vdb(built, dir / "as-built-test.vdb");
  const AsBuilt bands = as_built(file, dir / "as-built-test.vdb");
  EXPECT_EQ(file.band(), 2.0);
  EXPECT_EQ(bands.over_within.voxel_count(), 5 * (box.hi.y - box.lo.y));
  EXPECT_EQ(bands.over_beyond.voxel_count(), 9);
  EXPECT_EQ(bands.built.voxel_count(), built.voxel_count());
  EXPECT_EQ(bands.under_within.voxel_count() + bands.under_beyond.voxel_count(), 1);
  ReportRequest request;
  request.plan = dir;
  request.output = dir / "as-built.html";
  request.as_built = dir / "as-built-test.vdb";
  request.snapshots = false;
  const nlohmann::json data = page_data(slurp(write_report(request).page));
  EXPECT_DOUBLE_EQ(data["as_built"]["bands"]["over_beyond"]["volume"].get<double>(), bands.over_beyond.volume());
  EXPECT_GT(data["as_built"]["built"]["triangles"].get<int>(), 0);
}

TEST(Report, RefusesWhatIsNotAPlanDirectoryAndWritesNothing) {
  const fs::path dir = fs::temp_directory_path() / ("hybridctl-report-empty-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  ReportRequest request;
  request.plan = dir;
  try {
    write_report(request);
    ADD_FAILURE() << "no error for a directory without plan.json";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find((dir / "plan.json").string()), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir / "report.html"));
  fs::remove_all(dir);
}

TEST(Report, OverItsSizeBudgetIsRefusedAndNothingIsWritten) {
  const fs::path dir = bracket();
  ReportRequest request;
  request.plan = dir;
  request.output = dir / "too-big.html";
  request.size_budget = 1 << 20;  // three.js alone is 0.85 MB
  try {
    write_report(request);
    ADD_FAILURE() << "a page over its budget was written";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("over its budget"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir / "too-big.html"));
  EXPECT_FALSE(fs::exists(dir / "too-big-overview.png"));
}

TEST(Report, NamesTheMissingPackageWhenThreeJsIsAbsent) {
  ReportRequest request;
  request.plan = bracket();
  request.output = request.plan / "no-three.html";
  request.three_js_directory = "/nonexistent/three";
  try {
    write_report(request);
    ADD_FAILURE() << "no error without three.js";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("libjs-three"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(request.output));
}

}  // namespace
}  // namespace hybridctl::report
