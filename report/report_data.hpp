#pragma once
// What the report shows, gathered from a plan directory (and a dry run's output): the
// page's data document (JSON; docs/report.md, "Data") and the meshes and toolpaths the
// PNG snapshots draw. Fields other engineers' plan.json may carry (rejected candidates,
// per-plan gap, deviation places) are passed through when present, never required.

#include <nlohmann/json.hpp>
#include <optional>
#include <vector>

#include "report/report.hpp"
#include "report/report_exact.hpp"
#include "report/report_mesh.hpp"
#include "report/report_toolpaths.hpp"

namespace hybridctl::report {

// A plan as the snapshots draw it.
struct PlanView {
  std::vector<IndexedMesh> states;  // the solid after each action
  std::vector<ActionPath> paths;    // each action's toolpath (empty when it has none)
  std::optional<TriangleDeviations> exact;  // per triangle of ReportData::design_stl; none: not measured
};

struct ReportData {
  nlohmann::json document;
  IndexedMesh design;
  IndexedMesh design_stl;  // the design's own STL, as exact verification samples it (empty: none)
  double tolerance = 0;    // mm, the part's
  std::vector<IndexedMesh> violating;  // each violating atom
  std::vector<PlanView> plans;
  std::size_t triangles = 0, segments = 0;
  int actions = 0;
};

ReportData report_data(const ReportRequest& request);

// The encoding the page decodes (report.js, decodeMesh).
nlohmann::json mesh_json(const IndexedMesh& mesh);

}  // namespace hybridctl::report
