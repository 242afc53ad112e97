#pragma once
// Small hand-made plan files for validation tests on the bundled hybrid machine.

#include <string>
#include <vector>

#include "config/machine_loader.hpp"
#include "geometry/shapes.hpp"
#include "plan/plan_file.hpp"

namespace hybridctl::validation::cases {

using geometry::Box3;
using geometry::Solid;

inline const config::Machine& machine() {
  static const config::Machine m = config::load_machine("examples/machines/hybrid-3axis.yaml");
  return m;
}

// A plan file built by hand: 0.5 mm voxels over 40 x 30 x 24 mm from the origin.
struct Case {
  plan::PlanFile file;

  explicit Case(double tolerance) {
    file.machine_name = machine().name;
    file.lattice = {0.5, {0, 0, 0}};
    file.domain = {{0, 0, 0}, {80, 60, 48}};
    file.tolerance = tolerance;
    file.design = Solid(file.lattice, file.domain);
  }
  Solid box(Box3 b) const { return geometry::make_box(file.lattice, b); }
  int add(const std::string& kind, config::Mode mode, const std::string& capability, const std::string& setup,
          const Solid& region, int tool_number = 0) {
    plan::PlanFilePrimitive p;
    p.name = "P" + std::to_string(file.primitives.size() + 1);
    p.label = kind + " " + capability;
    p.kind = *config::primitive_kind_named(kind);
    p.mode = mode;
    p.capability = capability;
    p.setup = setup;
    p.tool_number = tool_number;
    p.region = intersect(region, Solid::filled(file.lattice, file.domain));
    file.primitives.push_back(std::move(p));
    return int(file.primitives.size()) - 1;
  }
  int stock(const Solid& region) { return add("raw-stock", config::Mode::Additive, "block", "", region); }
  int deposit(const Solid& region, const std::string& setup = "top") {
    return add("u-am", config::Mode::Additive, "ded", setup, region);
  }
  int mill(const Solid& region, int tool, const std::string& setup = "top") {
    return add("sm-cons", config::Mode::Subtractive, "T" + std::to_string(tool), setup, region, tool);
  }
  plan::PlanFilePlan plan(std::vector<int> actions) const {
    plan::PlanFilePlan p;
    for (int a : actions) p.actions.push_back({a, 0, 0});
    return p;
  }
};

}  // namespace hybridctl::validation::cases
