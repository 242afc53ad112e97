// The job report of a real plan directory (the bundled bracket on the bundled machine at a
// coarse voxel, and the same part on a machine with only a mill): one self-contained page
// within its size budget, with every plan's states and toolpaths, the offending atoms of a
// part that cannot be made, and PNG snapshots that show the part; nothing written for bad
// input or a page over budget. The flanged hub, planned and proven as `plan` does it: each
// plan's exact deviation painted on the STL's own facets, agreeing with plan.json.

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

namespace hybridctl::report {
namespace {

namespace fs = std::filesystem;

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

const fs::path& test_root() {
  static const fs::path root = fs::temp_directory_path() / ("hybridctl-report-test-" + std::to_string(::getpid()));
  return root;
}

// The plans made for these tests go when the program ends.
class RemoveTestPlans : public ::testing::Environment {
 public:
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(test_root(), ec);
  }
};
const auto* const kRemoveTestPlans = ::testing::AddGlobalTestEnvironment(new RemoveTestPlans);

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

nlohmann::json page_data(const std::string& page) {
  const std::string open = "<script type=\"application/json\" id=\"report-data\">";
  const std::size_t from = page.find(open) + open.size();
  return nlohmann::json::parse(page.substr(from, page.find("</script>", from) - from));
}

// The share of a PNG's pixels that are not the page's background: the snapshot shows something.
double drawn_share(const fs::path& png_path) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  EXPECT_TRUE(png_image_begin_read_from_file(&image, png_path.c_str())) << png_path;
  image.format = PNG_FORMAT_RGB;
  std::vector<unsigned char> rgb(PNG_IMAGE_SIZE(image));
  EXPECT_TRUE(png_image_finish_read(&image, nullptr, rgb.data(), 0, nullptr));
  std::size_t drawn = 0;
  for (std::size_t i = 0; i + 2 < rgb.size(); i += 3)
    if (std::abs(rgb[i] - 245) > 12 || std::abs(rgb[i + 1] - 247) > 12 || std::abs(rgb[i + 2] - 250) > 12) ++drawn;
  return double(drawn) / double(rgb.size() / 3);
}

// Little-endian values of a base64 field of the page (report_mesh.hpp's base64).
template <class T>
std::vector<T> decoded(const std::string& text) {
  static const std::string digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::vector<unsigned char> bytes;
  std::uint32_t bits = 0;
  int count = 0;
  for (const char c : text) {
    if (c == '=') break;
    bits = (bits << 6) | std::uint32_t(digits.find(c));
    if ((count += 6) >= 8) bytes.push_back(static_cast<unsigned char>(bits >> (count -= 8)));
  }
  std::vector<T> out(bytes.size() / sizeof(T));
  std::memcpy(out.data(), bytes.data(), out.size() * sizeof(T));
  EXPECT_EQ(bytes.size(), out.size() * sizeof(T)) << "not a whole number of values";
  return out;
}

// The flanged hub on the bundled machine at its own settings, planned as `plan` does it:
// every plan proven by execution and verified against the STL (plan.json's deviation.exact),
// with the STL copied into the directory as design.stl.
fs::path proven_hub() {
  const fs::path dir = test_root() / "proven-hub";
  if (fs::exists(dir / "plan.json")) return dir;
  const std::string stl = HYBRIDCTL_SOURCE_DIR "/examples/parts/flanged-hub.stl";
  const std::string text = config::read_machine_text(HYBRIDCTL_SOURCE_DIR "/examples/machines/hybrid-3axis.yaml");
  const config::Machine machine = config::parse_machine(text, "hybrid-3axis.yaml");
  const geometry::TriangleMesh part = geometry::read_stl(stl);
  planner::PlanningOptions options;
  // Two plans, which mill with flat end mills only: wall finishing puts the walls within a
  // few thousandths of the STL (docs/toolpaths.md: the arcs stand up to 0.001 mm out of
  // their chords, the passes 0.0012 mm); at a tolerance of 0.004 mm that excess is half the
  // scale's ramp, enough to paint. (The third, the ball's, would finish its top at a
  // 0.0013 mm scallop: a minute more of planning.)
  options.top_k = 2;
  options.tolerance = 0.004;
  validation::ExecutionOptions proving;
  proving.surfaces = std::make_shared<verification::DesignSurfaces>(part, stl);
  planner::validate_by_execution(options, validation::plan_validator(machine, std::move(proving)), machine.name);
  const planner::PlanningResult result = planner::plan_part(part, stl, machine, options);
  planner::write_plan_directory(result, {stl, "hybrid-3axis.yaml", machine.name, text}, dir);
  return dir;
}

// The "the report shows the exact deviation on the design's own mesh": the page
// carries the STL's own triangles (not a voxel surface) and, per plan, one figure per
// triangle, whose largest excess and gouge are the plan's exact figures in plan.json.
TEST(Report, PaintsEachPlansExactDeviationOnTheDesignsOwnMesh) {
  const fs::path dir = proven_hub();
  const nlohmann::json plan = nlohmann::json::parse(slurp(dir / "plan.json"));
  ASSERT_FALSE(plan["plans"].empty());
  ReportRequest request;
  request.plan = dir;
  const ReportResult r = write_report(request);
  const nlohmann::json data = page_data(slurp(r.page));

  const std::size_t stl_triangles = geometry::read_stl(dir / "design.stl").triangles.size();
  ASSERT_EQ(stl_triangles, 380u);  // the bundled hub: a clean STL, every facet with area
  const nlohmann::json& surface = data["design"]["surface"];
  ASSERT_FALSE(surface.contains("error")) << surface["error"];
  EXPECT_EQ(surface["file"], "design.stl");
  EXPECT_EQ(surface["triangles"].get<std::size_t>(), stl_triangles);
  EXPECT_EQ(surface["mesh"]["triangles"].get<std::size_t>(), stl_triangles);
  EXPECT_EQ(surface["mesh"]["voxel"].get<double>(), 0.0) << "the STL itself, not a voxel surface";

  // The STL's own facets, in its order (the maps are per facet in this order).
  const geometry::TriangleMesh stl = geometry::read_stl(dir / "design.stl");
  {
    const nlohmann::json& m = surface["mesh"];
    const std::vector<std::uint16_t> q = decoded<std::uint16_t>(m["p"]), index = decoded<std::uint16_t>(m["i16"]);
    ASSERT_EQ(index.size(), 3 * stl_triangles);
    for (std::size_t t = 0; t < stl_triangles; ++t)
      for (int v = 0; v < 3; ++v) {
        const double expected[3] = {stl.triangles[t][v].x, stl.triangles[t][v].y, stl.triangles[t][v].z};
        for (int c = 0; c < 3; ++c) {
          const double lo = m["lo"][c].get<double>(), hi = m["hi"][c].get<double>();
          ASSERT_NEAR(lo + q[index[3 * t + v] * 3 + c] / 65535.0 * (hi - lo), expected[c], 1e-3) << "facet " << t;
        }
      }
  }

  ASSERT_EQ(data["plans"].size(), plan["plans"].size());
  std::vector<float> plan_1_excess;
  for (std::size_t k = 0; k < data["plans"].size(); ++k) {
    SCOPED_TRACE("plan " + std::to_string(k + 1));
    const nlohmann::json& exact = plan["plans"][k]["deviation"]["exact"];
    ASSERT_TRUE(exact.is_object()) << "plan.json carries no exact figures: the plans were not verified";
    const nlohmann::json& map = data["plans"][k]["exact_map"];
    ASSERT_FALSE(map.contains("error")) << map["error"];
    EXPECT_EQ(map["triangles"].get<std::size_t>(), stl_triangles);
    const std::vector<float> excess = decoded<float>(map["excess"]), gouge = decoded<float>(map["gouge"]);
    const std::vector<std::uint16_t> action = decoded<std::uint16_t>(map["action"]);
    const std::vector<std::uint8_t> deposited = decoded<std::uint8_t>(map["deposited"]);
    ASSERT_EQ(excess.size(), stl_triangles);
    ASSERT_EQ(gouge.size(), stl_triangles);
    ASSERT_EQ(action.size(), stl_triangles);
    ASSERT_EQ(deposited.size(), stl_triangles);
    if (k == 0) plan_1_excess = excess;
    // Replayed as validation ran it: the same figures, places, actions and lines.
    EXPECT_NEAR(*std::max_element(excess.begin(), excess.end()), exact["max_excess_mm"].get<double>(), 1e-6);
    EXPECT_NEAR(*std::max_element(gouge.begin(), gouge.end()), exact["max_gouge_mm"].get<double>(), 1e-6);
    EXPECT_EQ(map["summary"], exact);
    // The worst facet names the action that left the plan's largest excess.
    const std::size_t worst = std::size_t(std::max_element(excess.begin(), excess.end()) - excess.begin());
    if (excess[worst] >= gouge[worst]) {
      EXPECT_EQ(action[worst], exact["excess"]["action"].get<int>());
    }
    // The hub is milled from a plate: not a facet is left as deposited, and most of the
    // surface is off the STL by something, not painted as exactly on it (at least by the
    // wall finishing's clearance, 0.0002 mm).
    EXPECT_EQ(std::count(deposited.begin(), deposited.end(), 1), 0);
    EXPECT_GT(std::count_if(excess.begin(), excess.end(), [](float e) { return e > 0.0001f; }), 100);
    EXPECT_EQ(map["beyond_triangles"].get<int>(), 0);  // within the tolerance, as plan.json says
  }
  // Plan 1's map is, facet by facet, the largest excess of the samples cut from that facet:
  // the plan replayed here as validation runs it and measured with every sample kept.
  {
    const plan::PlanFile file = plan::read_plan_file(dir);
    const config::Machine machine = plan::plan_machine(file, {}).machine;
    verification::DesignSurfaces surfaces;
    const verification::DesignSurface* surface_of_plan = surfaces.for_plan(file);
    ASSERT_NE(surface_of_plan, nullptr);
    validation::ExecutionOptions options;
    options.verify_exactly = false;
    const validation::Execution run = validation::execute_plan(file, file.plans[0], machine, options);
    const verification::SurfaceDeviation measured = verification::measure_program(
        *surface_of_plan, machine, run.program, plan::start_stock(file, file.plans[0], machine), {file.tolerance});
    std::vector<float> worst(stl_triangles, 0.0f);
    for (std::size_t i = 0; i < measured.samples.size(); ++i) {
      float& w = worst.at(surface_of_plan->samples()[i].triangle);
      w = std::max(w, float(measured.samples[i].excess));
    }
    EXPECT_EQ(worst, plan_1_excess);
  }
  // The snapshot of the map of the plan with the most excess: its facets with excess in the
  // orange of the scale, where the overview draws the whole design in grey.
  std::size_t most = 0;
  for (std::size_t k = 1; k < plan["plans"].size(); ++k)
    if (plan["plans"][k]["deviation"]["exact"]["max_excess_mm"].get<double>() >
        plan["plans"][most]["deviation"]["exact"]["max_excess_mm"].get<double>())
      most = k;
  ASSERT_GT(plan["plans"][most]["deviation"]["exact"]["max_excess_mm"].get<double>(), 0.0015);
  EXPECT_NE(std::find(r.snapshots.begin(), r.snapshots.end(), dir / "report-exact-1.png"), r.snapshots.end());
  const fs::path png = dir / ("report-exact-" + std::to_string(most + 1) + ".png");
  ASSERT_NE(std::find(r.snapshots.begin(), r.snapshots.end(), png), r.snapshots.end());
  EXPECT_EQ(r.snapshots.size(), 1 + 2 * plan["plans"].size());  // overview, a strip and a map per plan
  EXPECT_GT(drawn_share(png), 0.05);
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  ASSERT_TRUE(png_image_begin_read_from_file(&image, png.c_str()));
  image.format = PNG_FORMAT_RGB;
  std::vector<unsigned char> rgb(PNG_IMAGE_SIZE(image));
  ASSERT_TRUE(png_image_finish_read(&image, nullptr, rgb.data(), 0, nullptr));
  std::size_t orange = 0;
  for (std::size_t i = 0; i + 2 < rgb.size(); i += 3)
    if (rgb[i] > rgb[i + 2] + 40) ++orange;  // the warm side of the scale
  EXPECT_GT(double(orange) / double(rgb.size() / 3), 0.005) << "the map shows no excess";
}

// The scale the page and the snapshots share: neutral on the design, a ramp to the
// tolerance each way, and beyond it flat colours that the ramp never reaches.
TEST(Report, TheExactScaleSetsWhatIsBeyondTheToleranceApartBothWays) {
  const double tol = 0.5;
  const auto near = [](const std::array<float, 3>& a, const std::array<float, 3>& b) {
    return std::abs(a[0] - b[0]) + std::abs(a[1] - b[1]) + std::abs(a[2] - b[2]) < 1e-5;
  };
  const std::array<float, 3> zero = exact_colour(0, tol), excess_beyond = exact_colour(0.51, tol),
                             gouge_beyond = exact_colour(-0.51, tol);
  EXPECT_TRUE(near(exact_colour(2, tol), excess_beyond));
  EXPECT_TRUE(near(exact_colour(-2, tol), gouge_beyond));
  EXPECT_FALSE(near(excess_beyond, gouge_beyond));
  for (double v = -tol; v <= tol; v += tol / 50) {
    EXPECT_FALSE(near(exact_colour(v, tol), excess_beyond)) << v;
    EXPECT_FALSE(near(exact_colour(v, tol), gouge_beyond)) << v;
  }
  // Excess reddens (more red than blue), gouge blues, by how much it is.
  const std::array<float, 3> e = exact_colour(0.4, tol), g = exact_colour(-0.4, tol);
  EXPECT_GT(e[0] - e[2], zero[0] - zero[2] + 0.3f);
  EXPECT_GT(g[2] - g[0], zero[2] - zero[0] + 0.3f);
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
