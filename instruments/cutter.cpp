#include "instruments/cutter.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>

namespace hybridctl::instruments {

using Kind = geometry::AxialSection::Kind;

config::CuttingTool with_defaults(config::CuttingTool t) {
  if (!(t.diameter > 0)) throw std::invalid_argument("tool T" + std::to_string(t.number) + " has no diameter");
  if (!(t.flute_length > 0)) t.flute_length = 3 * t.diameter;
  if (!(t.shank.diameter > 0)) t.shank.diameter = t.diameter;
  if (!(t.shank.length > 0)) t.shank.length = 2 * t.diameter;
  if (!(t.holder.diameter > 0)) t.holder.diameter = 50;
  if (!(t.holder.length > 0)) t.holder.length = 60;
  if (!(t.step_down > 0)) t.step_down = 0.5 * t.diameter;
  if (!(t.step_over > 0)) t.step_over = 0.4 * t.diameter;
  if (t.type == config::ToolType::Ball) t.corner_radius = t.diameter / 2;
  if (t.type == config::ToolType::Bull && !(t.corner_radius > 0 && t.corner_radius < t.diameter / 2))
    throw std::invalid_argument("bull tool T" + std::to_string(t.number) + " needs 0 < corner_radius < diameter/2");
  if (t.type == config::ToolType::Flat) t.corner_radius = 0;
  if (!(t.feed > 0)) t.feed = 1000;
  if (!(t.plunge_feed > 0)) t.plunge_feed = 300;
  return t;
}

std::vector<geometry::AxialSection> Cutter::whole() const {
  std::vector<geometry::AxialSection> all = cutting;
  all.insert(all.end(), body.begin(), body.end());
  return all;
}

Cutter cutter_of(const config::CuttingTool& tool_in) {
  const config::CuttingTool tool = with_defaults(tool_in);
  const double r = tool.diameter / 2, flute = tool.flute_length;
  Cutter c;
  switch (tool.type) {
    case config::ToolType::Flat:
      c.cutting.push_back({Kind::Cylinder, 0, flute, r, 0, 0});
      break;
    case config::ToolType::Ball:
      c.cutting.push_back({Kind::Sphere, 0, r, r, r, 0});
      c.cutting.push_back({Kind::Cylinder, r, flute, r, 0, 0});
      break;
    case config::ToolType::Bull: {
      const double rc = tool.corner_radius;
      c.cutting.push_back({Kind::Torus, 0, rc, rc, rc, r - rc});
      c.cutting.push_back({Kind::Cylinder, rc, flute, r, 0, 0});
      break;
    }
  }
  const double shank_end = flute + tool.shank.length;
  c.body.push_back({Kind::Cylinder, flute, shank_end, tool.shank.diameter / 2, 0, 0});
  c.body.push_back({Kind::Cylinder, shank_end, std::numeric_limits<double>::infinity(), tool.holder.diameter / 2, 0, 0});
  return c;
}

double radius_squared_at(const std::vector<geometry::AxialSection>& profile, double z) {
  double best = -1;
  for (const geometry::AxialSection& s : profile) best = std::max(best, s.radius_squared_at(z));
  return best;
}

}  // namespace hybridctl::instruments
