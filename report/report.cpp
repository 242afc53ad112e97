#include "report/report.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>

#include <tbb/parallel_for.h>

#include "common/atomic_file.hpp"
#include "common/error.hpp"
#include "report/report_data.hpp"
#include "report/report_exact.hpp"
#include "report/report_page.hpp"
#include "report/snapshot.hpp"

namespace hybridctl::report {
namespace {

namespace fs = std::filesystem;

// The page's colours (report.js, kColours), for the snapshots to match it.
const Colour kDesign{0.62f, 0.68f, 0.76f};
const Colour kViolating{0.86f, 0.10f, 0.12f};
const Colour kAdditiveState{0.93f, 0.80f, 0.64f};
const Colour kSubtractiveState{0.74f, 0.81f, 0.90f};
const Colour kDeposit{0.80f, 0.25f, 0.00f};
const Colour kCut{0.00f, 0.36f, 0.72f};
const Colour kBeyondOutline{1.00f, 0.82f, 0.12f};  // 0xffd21f
const Colour kAsDeposited{0.07f, 0.66f, 0.29f};    // 0x13a84a

void grow(geometry::Box3& box, bool& any, const IndexedMesh& mesh) {
  for (std::size_t i = 0; i + 2 < mesh.positions.size(); i += 3) {
    const geometry::Vec3 p{mesh.positions[i], mesh.positions[i + 1], mesh.positions[i + 2]};
    if (!any) box = {p, p};
    any = true;
    box.min = {std::min(box.min.x, p.x), std::min(box.min.y, p.y), std::min(box.min.z, p.z)};
    box.max = {std::max(box.max.x, p.x), std::max(box.max.y, p.y), std::max(box.max.z, p.z)};
  }
}

// The process moves only: at the size of a tile, rapids and links would hide the part.
SnapshotLines path_lines(const ActionPath& path, std::vector<float>& points) {
  for (std::size_t s = 0; s < path.kinds.size(); ++s)
    if (path.kinds[s] == SegmentKind::Process)
      points.insert(points.end(), path.points.begin() + std::ptrdiff_t(s * 6), path.points.begin() + std::ptrdiff_t(s * 6 + 6));
  return {&points, {path.additive ? kDeposit : kCut}};
}

fs::path beside(const fs::path& page, const std::string& suffix) {
  return page.parent_path() / (page.stem().string() + suffix);
}

// The plan's strip: the solid after each action with the action's deposition or cuts.
Image plan_strip(const PlanView& plan, const geometry::Box3& bounds) {
  std::vector<std::vector<float>> points(plan.states.size());
  std::vector<SnapshotTile> strip;
  for (std::size_t a = 0; a < plan.states.size(); ++a) {
    const ActionPath* path = a < plan.paths.size() && plan.paths[a].makes_gcode ? &plan.paths[a] : nullptr;
    SnapshotTile tile{{{&plan.states[a], !path || path->additive ? kAdditiveState : kSubtractiveState, false}}, {}};
    if (path) tile.lines.push_back(path_lines(*path, points[a]));
    strip.push_back(std::move(tile));
  }
  return render_tiles(strip, bounds, std::min<int>(int(strip.size()), 5), 360, 270);
}

// A plan's exact deviation on the design's own mesh, from the page's direction: each facet
// of the STL in its colour (exact_colour), the facets beyond the tolerance outlined in
// yellow and those left as deposited dashed in green, as the page draws them (report.js).
Image exact_map(const ReportData& data, const TriangleDeviations& d, const geometry::Box3& bounds) {
  const IndexedMesh& mesh = data.design_stl;
  std::vector<Colour> colours(mesh.triangles());
  std::vector<float> outline, deposited;
  const auto edges = [&mesh](std::size_t t, std::vector<float>& out, double dash, double gap) {
    const std::vector<float>& p = mesh.positions;
    for (int e = 0; e < 3; ++e) {
      const std::size_t a = std::size_t(mesh.indices[t * 3 + e]) * 3, b = std::size_t(mesh.indices[t * 3 + (e + 1) % 3]) * 3;
      const double dx = p[b] - p[a], dy = p[b + 1] - p[a + 1], dz = p[b + 2] - p[a + 2];
      const double length = std::sqrt(dx * dx + dy * dy + dz * dz);
      for (double from = 0; from < length; from += gap > 0 ? dash + gap : length) {
        const double u = from / length, v = gap > 0 ? std::min(length, from + dash) / length : 1.0;
        out.insert(out.end(), {float(p[a] + dx * u), float(p[a + 1] + dy * u), float(p[a + 2] + dz * u),
                               float(p[a] + dx * v), float(p[a + 1] + dy * v), float(p[a + 2] + dz * v)});
      }
    }
  };
  for (std::size_t t = 0; t < colours.size(); ++t) {
    const double v = signed_deviation(d, t);
    colours[t] = exact_colour(v, data.tolerance);
    if (std::abs(v) > data.tolerance) edges(t, outline, 0, 0);
    if (d.deposited[t]) edges(t, deposited, 1.2, 0.8);
  }
  SnapshotTile tile{{{&mesh, kDesign, false, &colours}}, {}};
  if (!outline.empty()) tile.lines.push_back({&outline, {kBeyondOutline}, 3});
  if (!deposited.empty()) tile.lines.push_back({&deposited, {kAsDeposited}, 3});
  return render_tiles({tile}, bounds, 1, 960, 640);
}

std::vector<fs::path> write_snapshots(const ReportData& data, const fs::path& page) {
  geometry::Box3 bounds;
  bool any = false;
  grow(bounds, any, data.design);
  for (const PlanView& plan : data.plans)
    for (const IndexedMesh& m : plan.states) grow(bounds, any, m);
  for (const IndexedMesh& m : data.violating) grow(bounds, any, m);
  if (!any) return {};
  // The exact maps frame the design alone.
  geometry::Box3 design_bounds;
  bool any_design = false;
  grow(design_bounds, any_design, data.design_stl);
  // The overview, then one strip per plan with states, then each plan's exact deviation
  // on the design's mesh; rendered in parallel.
  std::vector<fs::path> written{beside(page, "-overview.png")};
  std::vector<std::size_t> strips, maps;
  for (std::size_t k = 0; k < data.plans.size(); ++k)
    if (!data.plans[k].states.empty()) {
      strips.push_back(k);
      written.push_back(beside(page, "-plan-" + std::to_string(k + 1) + ".png"));
    }
  for (std::size_t k = 0; k < data.plans.size(); ++k)
    if (data.plans[k].exact && !data.design_stl.empty()) {
      maps.push_back(k);
      written.push_back(beside(page, "-exact-" + std::to_string(k + 1) + ".png"));
    }
  tbb::parallel_for(std::size_t(0), written.size(), [&](std::size_t i) {
    if (i == 0) {
      SnapshotTile overview{{{&data.design, kDesign, false}}, {}};
      for (const IndexedMesh& m : data.violating) overview.meshes.push_back({&m, kViolating, true});
      write_png(render_tiles({overview}, bounds, 1, 960, 640), written[0]);
    } else if (i <= strips.size()) {
      write_png(plan_strip(data.plans[strips[i - 1]], bounds), written[i]);
    } else {
      write_png(exact_map(data, *data.plans[maps[i - 1 - strips.size()]].exact, design_bounds), written[i]);
    }
  });
  return written;
}

}  // namespace

ReportResult write_report(const ReportRequest& request) {
  const fs::path plan_dir = fs::is_directory(request.plan) ? request.plan : request.plan.parent_path();
  ReportResult result;
  result.page = request.output.empty() ? plan_dir / "report.html" : request.output;
  const ReportData data = report_data(request);
  const std::string page = report_page(data.document, request.three_js_directory);
  if (page.size() > request.size_budget)
    throw InputError(result.page.string() + ": the report would be " + std::to_string(page.size() >> 20) +
                     " MiB, over its budget of " + std::to_string(request.size_budget >> 20) +
                     " MiB: lower the triangle budgets (docs/report.md)");
  AtomicFile file(result.page);
  {
    std::ofstream out(file.temp_path(), std::ios::binary);
    out << page;
    out.flush();
    if (!out) throw InputError(result.page.string() + ": cannot write");
  }
  file.commit();
  result.bytes = page.size();
  result.triangles = data.triangles;
  result.segments = data.segments;
  result.plans = int(data.plans.size());
  result.actions = data.actions;
  if (request.snapshots) result.snapshots = write_snapshots(data, result.page);
  return result;
}

}  // namespace hybridctl::report
