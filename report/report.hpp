#pragma once
// The job report (docs/report.md): one self-contained HTML page for a plan directory
// (`hybridctl plan -o DIR`), and after a dry run what it built, with PNG snapshots of the
// main views beside it. Everything the page needs is inlined (three.js from Debian's
// libjs-three, read at report time; the page's script and styles; the data), so it opens
// offline in any current browser and can be mailed as one file.

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

namespace hybridctl::plan {
struct PlanFile;
}

namespace hybridctl::report {

// Debian's libjs-three (r111): its UMD build and the orbit controls of its examples.
inline constexpr const char* kThreeJsDirectory = "/usr/share/javascript/three";

// Triangles per mesh; a solid whose surface needs more is meshed on coarser voxels
// (report_mesh.hpp). With the defaults the bundled bracket's report with 5 plans stays
// under the size budget below (docs/report.md).
struct MeshBudget {
  std::size_t design = 60000;
  std::size_t primitive = 8000;
  std::size_t atom_class = 20000;     // must-in, must-out, free: one mesh each
  std::size_t violating_atom = 4000;  // each violating atom
  std::size_t state = 8000;           // each plan's solid after each action
  std::size_t as_built = 20000;       // as built and each deviation band
  // The design's own STL, painted with each plan's exact deviation: sent as it is, never
  // coarsened (it is the surface measured); an STL with more triangles gets no map.
  std::size_t design_stl = 200000;
};

// The page's size budget: refused (nothing written) beyond it, so a report always mails.
inline constexpr std::size_t kDefaultSizeBudget = 20u << 20;

struct ReportRequest {
  std::filesystem::path plan;        // plan.json or its directory
  // The plan as `plan` holds it (`plan --report`), equal to what PLAN_DIR reads back as
  // (planner::to_plan_file): its solids are not read back from the .vdb files. Null: read.
  const plan::PlanFile* in_memory = nullptr;
  std::filesystem::path output;      // the page; empty: PLAN_DIR/report.html
  std::filesystem::path as_built;    // optional: `sim serve --as-built` of a run of plan 1
  std::filesystem::path run_report;  // optional: `sim serve --report` of that run
  std::filesystem::path three_js_directory = kThreeJsDirectory;
  MeshBudget budget;
  std::size_t size_budget = kDefaultSizeBudget;  // bytes
  bool snapshots = true;             // PNGs beside the page
  // Plans (the best first) whose programs are replayed as validation runs them and measured
  // against the STL's real surface, for the exact deviation on the design's own mesh
  // (report_exact.hpp); 0: none.
  std::size_t exact_plans = 64;
};

struct ReportResult {
  std::filesystem::path page;
  std::vector<std::filesystem::path> snapshots;
  std::size_t bytes = 0;              // of the page
  std::size_t triangles = 0;          // in all its meshes
  std::size_t segments = 0;           // in all its toolpaths
  int plans = 0, actions = 0;
};

// Writes the page (temporary file, then rename) and the snapshots. Throws
// hybridctl::InputError for a plan directory that cannot be read (naming the file and
// what was expected), for a missing three.js (naming the package), and for a page over
// the size budget.
ReportResult write_report(const ReportRequest& request);

}  // namespace hybridctl::report
