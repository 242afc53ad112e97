#include "planner/atoms/fine_graining.hpp"

#include <algorithm>
#include <cstdio>
#include <map>
#include <optional>
#include <set>

#include "common/number_text.hpp"
#include "geometry/morphology.hpp"
#include "instruments/elements.hpp"
#include "instruments/support_rule.hpp"
#include "planner/primitives/support.hpp"

namespace hybridctl::planner {
namespace {

bool restrictable(const Primitive& p) {
  return p.kind == PrimitiveKind::UAm || p.kind == PrimitiveKind::OAm || p.kind == PrimitiveKind::SmMax ||
         p.kind == PrimitiveKind::SmCons;
}

// How far around a part of an atom the instrument must be free to work: a cutter's
// diameter (it passes by the part on every side), a bead's width; 0 when the machine
// does not know the capability.
double working_reach(const config::Machine& machine, const Primitive& p) {
  if (p.mode == Mode::Additive) {
    const config::AdditiveHead* head = machine.find_head(p.capability);
    return head ? head->bead.width : 0;
  }
  const config::CuttingTool* tool = machine.find_tool(p.tool_number);
  return tool ? tool->diameter : 0;
}

// The capability as a shop names it: "T4 (4 mm flat detail) in top", "ded in top".
std::string capability_text(const config::Machine& machine, const Primitive& p) {
  std::string what = p.capability;
  if (p.mode == Mode::Subtractive)
    if (const config::CuttingTool* tool = machine.find_tool(p.tool_number))
      what = "T" + std::to_string(tool->number) + " (" + tool->name + ")";
  return what + " in " + p.setup;
}

struct Candidate {
  Primitive primitive;
  bool exact = false;  // atom ∩ P' is exactly the part it was grown from
  double cost = 0;
};

// The neighbourhoods of an atom's part, by reach: the primitives that hold an atom share a
// few instruments, so each dilation is made once.
class Neighbourhoods {
 public:
  Neighbourhoods(const Solid& part, double tolerance, const IndexBox& domain)
      : part_(part), tolerance_(tolerance), domain_(domain) {}
  const Solid& within(double reach) {
    auto it = near_.find(reach);
    if (it == near_.end()) it = near_.emplace(reach, geometry::dilate(part_, geometry::Ball{reach + tolerance_}, domain_)).first;
    return it->second;
  }

 private:
  const Solid& part_;
  double tolerance_;
  IndexBox domain_;
  std::map<double, Solid> near_;
};

// The restriction of `p` to the neighbourhood of `part` that splits `atom` (leaves some
// of `other` out), or none.
std::optional<Candidate> restriction(const config::Machine& machine, const Primitive& p, const Solid& atom,
                                     const Solid& part, Neighbourhoods& around_part, const Solid& other,
                                     const Solid* present) {
  const double reach = working_reach(machine, p);
  if (reach <= 0) return std::nullopt;
  const Solid& near = around_part.within(reach);
  if (subtract(other, near).empty()) return std::nullopt;  // the other part lies within the reach
  Solid region = intersect(p.region, near);
  if (p.mode == Mode::Additive) {
    const config::AdditiveHead* head = machine.find_head(p.capability);
    const config::Setup* setup = machine.find_setup(p.setup);
    if (!head || !setup) return std::nullopt;
    region = self_supporting(region, instruments::approach_direction(setup->approach),
                             instruments::support_rule(head->support, atom.voxel_size()), present);
  }
  const Solid kept = intersect(region, atom);
  const std::int64_t n = kept.voxel_count();
  if (n == 0 || n == atom.voxel_count()) return std::nullopt;
  Candidate c{p, subtract(part, kept).empty() && subtract(kept, part).empty(), region.volume() * p.cost_per_mm3};
  c.primitive.region = std::move(region);
  return c;
}

std::vector<int> violating_atoms(const std::vector<AtomMeasures>& measures) {
  std::vector<int> out;
  for (std::size_t a = 0; a < measures.size(); ++a)
    if (measures[a].atom_class == AtomClass::Violating && !measures[a].sliver) out.push_back(int(a));
  std::stable_sort(out.begin(), out.end(), [&](int x, int y) { return measures[std::size_t(x)].volume > measures[std::size_t(y)].volume; });
  return out;
}

std::string why_unsplit(const config::Machine& machine, const std::vector<Primitive>& primitives,
                        const AtomDecomposition& atoms, int atom, const Solid& design) {
  std::set<std::string> tried;
  for (std::size_t i = 0; i < primitives.size(); ++i)
    if (atoms.code(atom).test(int(i)) && restrictable(primitives[i]) && working_reach(machine, primitives[i]) > 0)
      tried.insert(capability_text(machine, primitives[i]));
  // Whether any removal that spares the design reaches the outside part at all.
  const Solid outside = subtract(atoms.atom_solid(atom), design);
  std::int64_t reachable = 0;
  for (const Primitive& p : primitives)
    if (p.kind == PrimitiveKind::SmMax) reachable = std::max(reachable, intersect(outside, p.region).voxel_count());
  std::string s = "fine-graining tried ";
  if (tried.empty()) {
    s += "nothing: no machine capability holds it";
  } else {
    s += std::to_string(tried.size()) + " capabilit" + (tried.size() == 1 ? "y" : "ies") + " (";
    bool first = true;
    for (const std::string& t : tried) s += (first ? "" : ", ") + t, first = false;
    s += "), each deposit cut to a bead's reach around the part inside the design and each removal to a cutter's "
         "around the part outside it: none separates them, they lie within that reach of each other";
  }
  if (!outside.empty() && reachable == 0)
    s += "; no tool removes any of the " + trimmed_number(outside.volume(), 2) +
         " mm\u00B3 outside the design without cutting into the design (it is in no SM-max primitive)";
  return s;
}

}  // namespace

FineGraining fine_grain(const config::Machine& machine, const Solid& design, double tolerance, double sliver_threshold,
                        const Solid* present, std::vector<Primitive>& primitives, AtomDecomposition& atoms,
                        std::vector<AtomMeasures>& measures) {
  FineGraining out;
  const ToleranceZone zone = make_tolerance_zone(design, tolerance);
  for (int round = 0; round < kMaxFineGrainingRounds; ++round) {
    const std::vector<int> violating = violating_atoms(measures);
    if (violating.empty()) break;
    std::vector<Primitive> fresh;
    for (int a : violating) {
      if (out.added + int(fresh.size()) >= kMaxFineGrainedPrimitives) {
        out.capped = true;
        break;
      }
      const Solid atom = atoms.atom_solid(a);
      const Solid inside = intersect(atom, design), outside = subtract(atom, design);
      if (inside.empty() || outside.empty()) continue;
      Neighbourhoods around_inside(inside, tolerance, atoms.domain()), around_outside(outside, tolerance, atoms.domain());
      std::optional<Candidate> best;
      for (std::size_t i = 0; i < primitives.size(); ++i) {
        if (!atoms.code(a).test(int(i)) || !restrictable(primitives[i])) continue;
        // A deposit cut to what it should make (Ai), a removal to what it should take (Ao).
        const bool deposit = primitives[i].mode == Mode::Additive;
        std::optional<Candidate> c =
            deposit ? restriction(machine, primitives[i], atom, inside, around_inside, outside, present)
                    : restriction(machine, primitives[i], atom, outside, around_outside, inside, present);
        if (c && (!best || std::pair{c->exact, -c->cost} > std::pair{best->exact, -best->cost})) best = std::move(c);
      }
      if (!best) continue;
      const Solid& grown_from = best->primitive.mode == Mode::Additive ? inside : outside;
      const geometry::Box3 around = grown_from.bounding_box_mm();
      const geometry::Vec3 at{(around.min.x + around.max.x) / 2, (around.min.y + around.max.y) / 2, (around.min.z + around.max.z) / 2};
      char where[96];
      std::snprintf(where, sizeof where, ", around (%.1f, %.1f, %.1f)", at.x, at.y, at.z);
      best->primitive.label += where;
      fresh.push_back(std::move(best->primitive));
    }
    if (fresh.empty()) break;
    for (Primitive& p : fresh) {
      p.name = primitive_name(primitives.size());
      atoms.add_primitive(p.region);
      primitives.push_back(std::move(p));
    }
    out.added += int(fresh.size());
    ++out.rounds;
    measures = measure_atoms(atoms, design, zone, sliver_threshold);
  }
  for (int a : violating_atoms(measures)) out.unsplit.push_back({a, why_unsplit(machine, primitives, atoms, a, design)});
  return out;
}

}  // namespace hybridctl::planner
