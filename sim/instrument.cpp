#include "sim/instrument.hpp"

#include <limits>

namespace hybridctl::sim {

using Kind = geometry::AxialSection::Kind;

Cutter cutter_of(const config::CuttingTool& tool) {
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

Bead bead_of(const config::AdditiveHead& head) {
  return Bead{head.bead.shape, head.bead.width, head.bead.height, {}};
}

}  // namespace hybridctl::sim
