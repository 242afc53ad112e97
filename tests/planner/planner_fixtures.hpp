#pragma once
// Building planning problems from voxel primitives, as the planner does, so the tests
// exercise the symbolic search on real atom decompositions.

#include <algorithm>
#include <random>
#include <string>
#include <vector>

#include "geometry/shapes.hpp"
#include "planner/atoms/atoms.hpp"
#include "planner/search/search.hpp"

namespace hybridctl::planner::testing {

struct VoxelPrimitive {
  std::string name;
  Mode mode;
  bool raw = false;
  double cost = 1.0;
  Solid region;
};

struct VoxelProblem {
  std::vector<VoxelPrimitive> primitives;
  Solid design;
  IndexBox domain;
  AtomDecomposition atoms;
  PlanningProblem problem;
  std::vector<AtomMeasures> measures;
};

// Atoms of the primitives over `domain`, classified exactly against the design.
// `tolerance_mm` widens the band around the design where atoms are free either way.
inline VoxelProblem make_problem(std::vector<VoxelPrimitive> prims, const Solid& design, const IndexBox& domain,
                                 double tolerance_mm = 0) {
  AtomDecomposition atoms(design.lattice(), domain);
  for (const auto& p : prims) atoms.add_primitive(p.region);
  const auto measures = measure_atoms(atoms, design, make_tolerance_zone(design, tolerance_mm), 0);
  PlanningProblem problem;
  for (const auto& m : measures) {
    AtomSpec a;
    a.volume = m.volume;
    a.must_in = m.atom_class == AtomClass::MustIn || m.atom_class == AtomClass::Violating;
    a.must_out = m.atom_class == AtomClass::MustOut || m.atom_class == AtomClass::Violating;
    problem.atoms.push_back(a);
  }
  for (int i = 0; i < int(prims.size()); ++i) {
    PrimitiveSpec s;
    s.name = prims[std::size_t(i)].name;
    s.mode = prims[std::size_t(i)].mode;
    s.raw_stock = prims[std::size_t(i)].raw;
    s.cost_per_mm3 = prims[std::size_t(i)].cost;
    s.atoms = AtomSet(atoms.atom_count());
    for (int a = 0; a < atoms.atom_count(); ++a)
      if (atoms.code(a).test(i)) s.atoms.set(a);
    problem.primitives.push_back(s);
  }
  return {std::move(prims), design, domain, std::move(atoms), std::move(problem), measures};
}

// The plan carried out on the voxels themselves.
inline Solid evaluate(const VoxelProblem& vp, const Plan& plan) {
  Solid state(vp.design.lattice(), vp.domain);
  for (const PlanStep& step : plan.steps) {
    const VoxelPrimitive& p = vp.primitives[std::size_t(step.primitive)];
    state = p.mode == Mode::Additive ? unite(state, p.region) : subtract(state, p.region);
  }
  return intersect(state, Solid::filled(vp.design.lattice(), vp.domain));
}

inline Solid atoms_union(const VoxelProblem& vp, const AtomSet& set) {
  std::vector<bool> selected(static_cast<std::size_t>(vp.atoms.atom_count()));
  for (int a = 0; a < vp.atoms.atom_count(); ++a) selected[std::size_t(a)] = set.test(a);
  return vp.atoms.union_of(selected);
}

// A random instance whose design is the outcome of a random valid plan, so that
// solutions exist; primitives are boxes in a small grid.
inline VoxelProblem random_instance(std::mt19937& rng, int n) {
  const Lattice kUnit{1.0, {0, 0, 0}};
  std::uniform_real_distribution<double> at(0, 10), size(2, 8), cost(0.2, 3.0);
  std::vector<VoxelPrimitive> prims;
  for (int i = 0; i < n; ++i) {
    const Mode mode = i == 0 || rng() % 2 ? Mode::Additive : Mode::Subtractive;
    const double x = at(rng), y = at(rng), z = at(rng) / 3;
    prims.push_back({"P" + std::to_string(i + 1), mode, i == 0 && rng() % 2, cost(rng),
                     geometry::make_box(kUnit, {{x, y, z}, {x + size(rng), y + size(rng), z + size(rng) / 2}})});
  }
  const IndexBox domain{{0, 0, 0}, {18, 18, 8}};
  std::vector<int> order(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) order[std::size_t(i)] = i;
  std::shuffle(order.begin() + 1, order.end(), rng);  // P1 (additive) first
  const int length = 1 + int(rng() % unsigned(n));
  Solid design(kUnit, domain);
  for (int s = 0; s < length; ++s) {
    const VoxelPrimitive& p = prims[std::size_t(order[std::size_t(s)])];
    design = p.mode == Mode::Additive ? unite(design, p.region) : subtract(design, p.region);
  }
  design = intersect(design, Solid::filled(kUnit, domain));
  return make_problem(std::move(prims), design, domain);
}

}  // namespace hybridctl::planner::testing
