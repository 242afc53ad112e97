// The exact deviation in the job report (report/report_exact.hpp): the scale its colours
// follow, and on the flanged hub planned and proven as `plan` does it, each plan's exact
// deviation painted on the STL's own facets, agreeing with plan.json and with the plan
// replayed and measured here.

#include <gtest/gtest.h>
#include <png.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "geometry/mesh.hpp"
#include "plan/plan_file.hpp"
#include "plan/plan_machine.hpp"
#include "plan/start_stock.hpp"
#include "report/report.hpp"
#include "report/report_exact.hpp"
#include "validation/execution.hpp"
#include "verification/exact_deviation.hpp"
#include "page_reading.hpp"

namespace hybridctl::report {
namespace {

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

// The flanged hub on the bundled machine as `plan --tolerance 0.004 --top 2` made and proved
// it (the ctest fixture Fixture.PlanFlangedHubFinely: every plan proven by execution and
// verified against the STL, plan.json's deviation.exact, the STL copied in as design.stl),
// copied here so that this test's report does not overwrite the fixture's, which the
// browser test opens. Its two plans mill with flat end mills only: wall finishing puts the
// walls within a few thousandths of the STL (docs/toolpaths.md: the arcs stand up to
// 0.001 mm out of their chords, the passes 0.0012 mm); at a tolerance of 0.004 mm that
// excess is half the scale's ramp, enough to paint.
fs::path proven_hub() {
  const fs::path dir = test_root() / "proven-hub";
  if (fs::exists(dir / "plan.json")) return dir;
  const fs::path fixture = HYBRIDCTL_HUB_FINE_PLAN;
  if (!fs::exists(fixture / "plan.json"))
    throw std::runtime_error(fixture.string() + " has no plan.json: run the fixture Fixture.PlanFlangedHubFinely first");
  fs::create_directories(dir);
  fs::copy(fixture, dir, fs::copy_options::recursive | fs::copy_options::overwrite_existing);
  fs::remove(dir / "report.html");
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

}  // namespace
}  // namespace hybridctl::report
