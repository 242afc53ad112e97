#include "toolpaths/pocket_tool.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "instruments/elements.hpp"

namespace hybridctl::toolpaths::pocket {
namespace {

using geometry::AxialSection;
using instruments::kProfileSamplesPerVoxel;
using instruments::radius_squared_at;

constexpr double kInf = std::numeric_limits<double>::infinity();

// Adds `level` to the disc of `radius`, or starts that disc.
void add_cutter_disc(ToolModel& m, double radius, int level) {
  auto it = std::find_if(m.cutter_discs.begin(), m.cutter_discs.end(), [&](const auto& d) { return d.first == radius; });
  if (it == m.cutter_discs.end()) m.cutter_discs.push_back({radius, {level}});
  else it->second.push_back(level);
}

// The body's discs from its guard: a disc per distinct radius, from its lowest level.
void add_body_discs(ToolModel& m, double h) {
  for (const AxialSection& g : m.body_guard.sections) {
    const double radius = g.radius / h;
    const int from = int(std::lround(std::isinf(g.to) ? g.from / h : (g.from + g.to) / 2 / h));
    auto it = std::find_if(m.body_discs.begin(), m.body_discs.end(), [&](const auto& d) { return d.first == radius; });
    if (it == m.body_discs.end()) m.body_discs.push_back({radius, from});
    else it->second = std::min(it->second, from);
  }
}

}  // namespace

ToolModel make_tool(const config::CuttingTool& tool_in, double h) {
  const config::CuttingTool tool = instruments::with_defaults(tool_in);
  const instruments::Cutter cutter = instruments::cutter_of(tool);
  const double flute = tool.flute_length, shank_end = flute + tool.shank.length;
  ToolModel m;
  m.cutting = cutter.cutting;
  m.body = cutter.body;
  const std::vector<AxialSection> whole = cutter.whole();
  m.whole_guard = instruments::conservative_guard(whole, h);
  m.body_guard = instruments::conservative_guard(m.body, h);
  m.cutter_radius = tool.diameter / 2;
  m.max_radius = std::max({m.cutter_radius, tool.shank.diameter / 2, tool.holder.diameter / 2});
  m.body_first_level = int(std::floor(flute / h));
  add_body_discs(m, h);
  for (int t = 0; t <= int(std::floor(flute / h + 1e-9)); ++t) {
    const double r2 = radius_squared_at(m.cutting, t * h);
    if (r2 >= 0) add_cutter_disc(m, std::sqrt(r2) / h, t);
  }
  double widest = -1;
  for (int i = 0; i <= int(std::ceil((shank_end + h) / h)) * kProfileSamplesPerVoxel; ++i) {
    const double r2 = radius_squared_at(whole, i * h / kProfileSamplesPerVoxel);
    if (r2 < widest - 1e-9) m.widening = false;
    widest = std::max(widest, r2);
  }
  // The running maximum of the squared radius along the axis, sampled finely.
  m.profile_step = h / kProfileSamplesPerVoxel;
  double finite_end = 0;
  for (const auto* secs : {&m.cutting, &m.body})
    for (const AxialSection& s : *secs) finite_end = std::max(finite_end, std::isinf(s.to) ? s.from : s.to);
  const int n = int(std::ceil((finite_end + h) / m.profile_step)) + 1;
  auto running = [&](const std::vector<AxialSection>& secs) {
    std::vector<double> r(std::size_t(n), -1);
    double best = -1;
    for (int i = 0; i < n; ++i) {
      best = std::max(best, radius_squared_at(secs, i * m.profile_step));
      r[std::size_t(i)] = best;
    }
    return r;
  };
  m.run_whole = running(whole);
  m.run_cutter = running(m.cutting);
  m.run_body = running(m.body);
  return m;
}

double first_reach(const std::vector<double>& run, double step, double rho2) {
  const auto it = std::lower_bound(run.begin(), run.end(), rho2 - 1e-9);
  if (it == run.end()) return kInf;
  return std::max(0.0, double(it - run.begin() - 1) * step);
}

std::vector<ReachOffset> reach_offsets(const ToolModel& m, double h) {
  // The first height where the running maximum of the squared radius reaches rho^2, minus
  // one sample (rounded towards the tip: safe).
  auto first_reach_of = [&](const std::vector<double>& run, double rho2) { return first_reach(run, m.profile_step, rho2); };
  const int R = int(std::floor(m.max_radius / h));
  std::vector<ReachOffset> out;
  for (int dy = -R; dy <= R; ++dy)
    for (int dx = -R; dx <= R; ++dx) {
      const double rho2 = double(dx * dx + dy * dy) * h * h;
      ReachOffset o{dx, dy, first_reach_of(m.run_whole, rho2), first_reach_of(m.run_cutter, rho2),
                    first_reach_of(m.run_body, rho2)};
      if (!std::isinf(o.zmin_whole)) out.push_back(o);
    }
  return out;
}

}  // namespace hybridctl::toolpaths::pocket
