#include "plan/start_stock.hpp"

#include <algorithm>

#include "common/error.hpp"
#include "geometry/morphology.hpp"

namespace hybridctl::plan {

geometry::IndexBox simulated_domain(const PlanFile& file, const PlanFilePlan& plan, const config::Machine& machine) {
  geometry::IndexBox box = file.domain;
  if (plan.actions.empty()) return box;
  const PlanFilePrimitive& first = file.primitives.at(std::size_t(plan.actions.front().primitive));
  const geometry::IndexBox region = first.region.bounding_box();
  if (first.raw_stock() || first.mode != Mode::Additive || region.empty() || first.setup.empty()) return box;
  const auto setup = std::find_if(machine.setups.begin(), machine.setups.end(),
                                  [&](const config::Setup& s) { return s.name == first.setup; });
  if (setup == machine.setups.end())
    throw InputError(first.name + " (" + first.label + "): the machine '" + machine.name + "' has no setup '" +
                     first.setup + "'; expected one of its setups");
  // The plate lies on the side the approach points to (from +Z: below the region).
  switch (setup->approach) {
    case config::Approach::PlusZ: box.lo.z = std::max(box.lo.z, region.lo.z); break;
    case config::Approach::MinusZ: box.hi.z = std::min(box.hi.z, region.hi.z); break;
    case config::Approach::PlusX: box.lo.x = std::max(box.lo.x, region.lo.x); break;
    case config::Approach::MinusX: box.hi.x = std::min(box.hi.x, region.hi.x); break;
    case config::Approach::PlusY: box.lo.y = std::max(box.lo.y, region.lo.y); break;
    case config::Approach::MinusY: box.hi.y = std::min(box.hi.y, region.hi.y); break;
  }
  return box;
}

geometry::Solid start_stock(const PlanFile& file, const PlanFilePlan& plan, const config::Machine& machine) {
  geometry::Solid stock(file.lattice, simulated_domain(file, plan, machine));
  if (!plan.actions.empty()) {
    const PlanFilePrimitive& first = file.primitives.at(std::size_t(plan.actions.front().primitive));
    if (first.raw_stock())
      first.region.for_each_voxel([&](geometry::Index3 v) {
        if (file.domain.contains(v)) stock.set(v);
      });
  }
  return stock;
}

geometry::Solid spared_by_cuts(const PlanFile& file, const PlanFilePrimitive* action) {
  const bool removal = action && action->mode == Mode::Subtractive;
  const geometry::Solid kept = removal ? subtract(file.design, action->region) : file.design;
  return geometry::erode(kept, geometry::Ball{file.band()});
}

}  // namespace hybridctl::plan
