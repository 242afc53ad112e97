#include "report/report_exact.hpp"

#include <algorithm>
#include <exception>

#include "plan/start_stock.hpp"
#include "validation/execution.hpp"
#include "validation/prefix_cache.hpp"
#include "verification/design_surface.hpp"
#include "verification/exact_deviation.hpp"

namespace hybridctl::report {
namespace {

// The samples' figures gathered per triangle: the largest excess and gouge of its
// samples, the action of its worst sample, and whether most of its area is as deposited.
TriangleDeviations per_triangle(const verification::DesignSurface& surface, const verification::SurfaceDeviation& d) {
  const std::size_t n = surface.triangles().size();
  TriangleDeviations out;
  out.summary = d.summary;
  out.excess.assign(n, 0.0f);
  out.gouge.assign(n, 0.0f);
  out.action.assign(n, 0);
  out.deposited.assign(n, 0);
  std::vector<double> worst(n, -1), area(n, 0), deposited_area(n, 0);
  const std::vector<verification::SurfaceSample>& samples = surface.samples();
  for (std::size_t i = 0; i < samples.size() && i < d.samples.size(); ++i) {
    const verification::SampleDeviation& s = d.samples[i];
    const std::size_t t = samples[i].triangle;
    out.excess[t] = std::max(out.excess[t], float(s.excess));
    out.gouge[t] = std::max(out.gouge[t], float(s.gouge));
    const double w = std::max(s.excess, s.gouge);
    if (w > worst[t]) {
      worst[t] = w;
      out.action[t] = std::uint16_t(std::clamp(s.action, 0, 65535));
    }
    area[t] += samples[i].area;
    if (s.as_deposited) deposited_area[t] += samples[i].area;
  }
  for (std::size_t t = 0; t < n; ++t) out.deposited[t] = area[t] > 0 && deposited_area[t] > 0.5 * area[t] ? 1 : 0;
  return out;
}

std::array<float, 3> mix(const std::array<float, 3>& a, const std::array<float, 3>& b, double t) {
  const float u = float(std::clamp(t, 0.0, 1.0));
  return {a[0] + (b[0] - a[0]) * u, a[1] + (b[1] - a[1]) * u, a[2] + (b[2] - a[2]) * u};
}

}  // namespace

std::array<float, 3> exact_colour(double signed_mm, double tolerance) {
  // As report.js's kExact: 0xdde1e6 neutral, 0xf08a24 at +tol, 0xb3121a beyond; 0x3a86d4 at
  // -tol, 0x3b1a86 beyond.
  static const std::array<float, 3> kNeutral{0.867f, 0.882f, 0.902f}, kExcess{0.941f, 0.541f, 0.141f},
      kExcessBeyond{0.702f, 0.071f, 0.102f}, kGouge{0.227f, 0.525f, 0.831f}, kGougeBeyond{0.231f, 0.102f, 0.525f};
  const double tol = tolerance > 0 ? tolerance : 1e-9;
  if (signed_mm > tol) return kExcessBeyond;
  if (signed_mm < -tol) return kGougeBeyond;
  return signed_mm >= 0 ? mix(kNeutral, kExcess, signed_mm / tol) : mix(kNeutral, kGouge, -signed_mm / tol);
}

std::optional<ExactMaps> exact_maps(const plan::PlanFile& file, const config::Machine& machine, std::size_t max_plans,
                                    std::size_t max_triangles) {
  verification::DesignSurfaces surfaces;
  const verification::DesignSurface* surface = surfaces.for_plan(file);
  if (!surface) return std::nullopt;
  ExactMaps out;
  const std::filesystem::path copy = file.directory / plan::kDesignStl;
  std::error_code ec;
  out.stl = !file.directory.empty() && std::filesystem::is_regular_file(copy, ec) ? std::string(plan::kDesignStl) : file.part;
  geometry::TriangleMesh triangles;
  triangles.triangles = surface->triangles();
  out.design = indexed_mesh(triangles);
  if (out.design.triangles() > max_triangles) return out;
  // As validation runs each plan (export, run, plan's own validation): every action
  // planned against the material present, the whole program from the start stock. Plans
  // that begin alike resume from the prefix they share.
  validation::PrefixCache cache;
  validation::ExecutionOptions options;
  options.verify_exactly = false;  // measured below, keeping every sample's figures
  for (std::size_t k = 0; k < file.plans.size(); ++k) {
    const plan::PlanFilePlan& plan = file.plans[k];
    TriangleDeviations& map = out.plans.emplace_back();
    if (k >= max_plans) {
      map.error = "not replayed: the report replays the best " + std::to_string(max_plans) + " plans (--exact-plans)";
      continue;
    }
    try {
      const validation::Execution run = validation::execute_plan(file, plan, machine, options, &cache);
      if (!run.errors.empty()) {
        map.error = "the machine refused a line of the plan's program: " + run.errors.front();
        continue;
      }
      const verification::SurfaceDeviation measured = verification::measure_program(
          *surface, machine, run.program, plan::start_stock(file, plan, machine), {file.tolerance});
      map = per_triangle(*surface, measured);
    } catch (const std::exception& e) {
      map.error = e.what();
    }
  }
  return out;
}

}  // namespace hybridctl::report
