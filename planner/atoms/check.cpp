#include "planner/atoms/check.hpp"

#include <algorithm>
#include <bit>
#include <utility>
#include <cstdio>

namespace hybridctl::planner {
namespace {

std::string format(const char* fmt, double a, double b = 0, double c = 0) {
  char buf[128];
  std::snprintf(buf, sizeof buf, fmt, a, b, c);
  return buf;
}

// Why a plan must keep the atom and why it must not.
std::string reasons(const ViolatingAtom& v) {
  auto both = [](std::string a, const std::string& b) { return a.empty() ? b : b.empty() ? a : a + "; " + b; };
  const std::string keep = both(v.holds_core ? "it holds design deeper than the tolerance" : "",
                                v.holds_thin_feature ? "a feature thinner than twice the tolerance needs it" : "");
  const std::string drop = both(v.beyond_hull ? "it reaches farther than the tolerance outside the design" : "",
                                v.holds_thin_gap ? "a gap narrower than twice the tolerance needs it empty" : "");
  return "it must be kept (" + keep + ") and must not be (" + drop + ")";
}

std::string describe(const PlanningProblem& p, const ViolatingAtom& v) {
  std::string s = "a " + format("%.3g", v.volume) + " mm\u00B3 region around " +
                  format("(%.1f, %.1f, %.1f)", v.centroid.x, v.centroid.y, v.centroid.z) + " mm, " +
                  format("%.3g", v.volume_in_design) + " mm\u00B3 of it inside the design and " +
                  format("%.3g", v.volume - v.volume_in_design) + " mm\u00B3 outside; " + reasons(v) + "; ";
  bool any_additive = false, any_subtractive = false;
  std::string names;
  for (int i : v.primitives) {
    const PrimitiveSpec& prim = p.primitives[std::size_t(i)];
    (prim.mode == Mode::Additive ? any_additive : any_subtractive) = true;
    names += (names.empty() ? "" : ", ") + prim.name;
  }
  if (v.primitives.empty()) {
    s += "no primitive reaches it, so it stays empty";
  } else {
    s += "it lies in " + names + " and no other primitive splits it";
    if (!any_subtractive) s += "; no removal reaches it";
    if (!any_additive) s += "; no deposition reaches it";
  }
  return s;
}

// All-additive: the best outcome is the union of every primitive that deposits
// nothing forbidden; it must cover every must-in atom.
bool additive_only_possible(const PlanningProblem& p) {
  const int m = int(p.atoms.size());
  std::vector<bool> covered(std::size_t(m), false);
  for (const PrimitiveSpec& prim : p.primitives) {
    bool clean = true;
    for (int a = 0; a < m && clean; ++a) clean = !(prim.atoms.test(a) && p.atoms[std::size_t(a)].must_out);
    if (!clean) continue;
    for (int a = 0; a < m; ++a) covered[std::size_t(a)] = covered[std::size_t(a)] || prim.atoms.test(a);
  }
  for (int a = 0; a < m; ++a)
    if (p.atoms[std::size_t(a)].must_in && !covered[std::size_t(a)]) return false;
  return true;
}

// Stock then removals: some additive start holds every must-in atom, and the removals
// that spare every must-in atom clear every must-out atom it holds.
bool subtractive_only_possible(const PlanningProblem& p) {
  const int m = int(p.atoms.size());
  std::vector<bool> removable(std::size_t(m), false);
  for (const PrimitiveSpec& prim : p.primitives) {
    if (prim.mode != Mode::Subtractive) continue;
    bool spares = true;
    for (int a = 0; a < m && spares; ++a) spares = !(prim.atoms.test(a) && p.atoms[std::size_t(a)].must_in);
    if (!spares) continue;
    for (int a = 0; a < m; ++a) removable[std::size_t(a)] = removable[std::size_t(a)] || prim.atoms.test(a);
  }
  for (const PrimitiveSpec& start : p.primitives) {
    if (start.mode != Mode::Additive) continue;
    bool ok = true;
    for (int a = 0; a < m && ok; ++a) {
      const AtomSpec& atom = p.atoms[std::size_t(a)];
      if (atom.must_in && !start.atoms.test(a)) ok = false;
      if (atom.must_out && start.atoms.test(a) && !removable[std::size_t(a)]) ok = false;
    }
    if (ok) return true;
  }
  return false;
}

// A must-in atom is made by the last deposit that holds it, after which no removal that
// holds it may come; every must-out atom that deposit holds is then present, and only a
// removal that spares the atom can clear it. So some deposit holding the atom must hold
// only must-out atoms that some removal sparing it holds. (A deposit lays all its atoms: the
// search refuses one the state keeps out of reach or without footing, it does not cut it.)
// For each atom that has none, a sentence naming the deposits and what each leaves.
std::vector<std::pair<int, std::string>> atoms_no_deposit_makes(const PlanningProblem& p,
                                                                const std::vector<AtomMeasures>& measures) {
  const int m = int(p.atoms.size());
  AtomSet must_out(m);
  for (int a = 0; a < m; ++a)
    if (p.atoms[std::size_t(a)].must_out) must_out.set(a);
  std::vector<std::pair<int, std::string>> out;
  for (int a = 0; a < m; ++a) {
    if (!p.atoms[std::size_t(a)].must_in) continue;
    AtomSet sparing(m);
    for (const PrimitiveSpec& prim : p.primitives)
      if (prim.mode == Mode::Subtractive && !prim.atoms.test(a))
        for (std::size_t w = 0; w < sparing.words().size(); ++w) sparing.words()[w] |= prim.atoms.words()[w];
    std::string left;
    int deposits = 0;
    bool made = false;
    for (const PrimitiveSpec& prim : p.primitives) {
      if (prim.mode != Mode::Additive || !prim.atoms.test(a)) continue;
      ++deposits;
      int stuck = -1;
      for (std::size_t w = 0; w < sparing.words().size() && stuck < 0; ++w)
        if (const std::uint64_t bad = prim.atoms.words()[w] & must_out.words()[w] & ~sparing.words()[w])
          stuck = int(w * 64) + std::countr_zero(bad);
      if (stuck < 0) {
        made = true;
        break;
      }
      if (deposits <= 3) {
        const AtomMeasures& b = measures[std::size_t(stuck)];
        left += (left.empty() ? "" : "; ") + prim.name + " leaves " + format("%.3g", b.volume) + " mm\u00B3 around " +
                format("(%.1f, %.1f, %.1f)", b.centroid.x, b.centroid.y, b.centroid.z) + " mm";
      }
    }
    if (made) continue;
    out.emplace_back(a, deposits == 0 ? std::string("no deposit holds it")
                                      : "every deposit that holds it (" + std::to_string(deposits) +
                                            ") also lays material outside the design that only removals cutting into it "
                                            "clear (" + left + (deposits > 3 ? "; ..." : "") + ")");
  }
  return out;
}

// An atom that rules the part out, located, with the primitives holding it and what the
// tolerance zone says of it; the caller writes its description.
}  // namespace

ViolatingAtom located_atom(const PlanningProblem& p, const AtomMeasures& m, int a, const Lattice& lattice) {
  ViolatingAtom va;
  va.atom = a;
  va.code = m.code.bits(int(p.primitives.size()));
  for (int i = 0; i < int(p.primitives.size()); ++i)
    if (m.code.test(i)) va.primitives.push_back(i);
  va.volume = m.volume;
  va.volume_in_design = m.volume_in_design;
  va.bounds = lattice.extent(m.bounding_box);
  va.centroid = m.centroid;
  va.holds_core = m.voxels_in_core > 0;
  va.holds_thin_feature = m.thin_feature;
  va.beyond_hull = m.voxels_beyond_hull > 0;
  va.holds_thin_gap = m.thin_gap;
  return va;
}

Verdict core_verdict(const PlanningProblem& p, const CoreProof& proof, const std::vector<AtomMeasures>& measures,
                     const Lattice& lattice) {
  Verdict v;
  v.outcome = Verdict::Outcome::NotManufacturable;
  v.decided_without_search = true;
  int design = 0;
  std::vector<char> only_by_cutting;  // per violation, as built
  for (const int a : proof.core) {
    const AtomMeasures& m = measures[std::size_t(a)];
    ViolatingAtom va = located_atom(p, m, a, lattice);
    const bool in = p.atoms[std::size_t(a)].must_in, out = p.atoms[std::size_t(a)].must_out;
    const bool cut_free = cleared_only_by_cutting(p, a);
    design += in;
    std::string names;
    for (std::size_t k = 0; k < va.primitives.size() && k < 4; ++k)
      names += (k ? ", " : "") + p.primitives[std::size_t(va.primitives[k])].name;
    if (va.primitives.size() > 4) names += " and " + std::to_string(va.primitives.size() - 4) + " more";
    va.description = "a " + format("%.3g", m.volume) + " mm\u00B3 region " +
                     (in ? "of the design" : out ? "outside the design" : "in the planning band") + " around " +
                     format("(%.1f, %.1f, %.1f)", m.centroid.x, m.centroid.y, m.centroid.z) + " mm" +
                     (in ? " (must be made)" : out ? " (must be left empty)" : " (carries or blocks the others)") +
                     (names.empty() ? ", in no primitive" : ", in " + names) +
                     (cut_free ? "; no removal reaches it without cutting the design" : "");
    v.violations.push_back(std::move(va));
    only_by_cutting.push_back(cut_free);
  }
  // First the air no removal clears without cutting the part (a closed channel, a corner
  // no cutter gets into): what the proof is about. After it the design and the air a way
  // around it would spoil, the largest first (the lid and walls, not a row of voxels along
  // an edge that only shows what an undersized deposit leaves out), and the band's atoms
  // last. Without such air, the atoms fewest primitives hold (a roof, a slot's edge) before
  // the base they stand on.
  const bool hearted = std::count(only_by_cutting.begin(), only_by_cutting.end(), 1) > 0;
  std::vector<std::size_t> order(v.violations.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  const auto in_band = [&](std::size_t i) {
    const AtomSpec& spec = p.atoms[std::size_t(v.violations[i].atom)];
    return !spec.must_in && !spec.must_out;
  };
  std::sort(order.begin(), order.end(), [&](std::size_t i, std::size_t j) {
    const ViolatingAtom &x = v.violations[i], &y = v.violations[j];
    if (only_by_cutting[i] != only_by_cutting[j]) return only_by_cutting[i] > only_by_cutting[j];
    if (hearted && in_band(i) != in_band(j)) return in_band(j);
    if (hearted || x.primitives.size() == y.primitives.size()) return x.volume > y.volume;
    return x.primitives.size() < y.primitives.size();
  });
  std::vector<ViolatingAtom> sorted;
  std::string heart;
  int hearts = 0;
  for (const std::size_t i : order) {
    if (only_by_cutting[i]) {
      const ViolatingAtom& x = v.violations[i];
      heart += std::string(hearts++ ? "; " : "") + "a " + format("%.3g", x.volume) + " mm\u00B3 region around " +
               format("(%.1f, %.1f, %.1f)", x.centroid.x, x.centroid.y, x.centroid.z) + " mm";
    }
    sorted.push_back(std::move(v.violations[i]));
  }
  v.violations = std::move(sorted);
  v.summary = "no sequence of the " + std::to_string(p.primitives.size()) +
              " primitives gets these " + std::to_string(proof.core.size()) + " atoms right together (" +
              std::to_string(design) + " of the design), whatever the other atoms do: deposits cannot reach under "
              "material already there or lay a first layer on nothing, and removals cut what they hold (" +
              std::to_string(proof.joined[0]) + " of the atoms showed a deposit out of reach, " +
              std::to_string(proof.joined[1]) + " a first layer with nothing under it, " + std::to_string(proof.joined[2]) +
              " were wrong at the end of a plan; proven over " + std::to_string(proof.states) + " states of " +
              std::to_string(proof.rounds) + " projections)";
  if (hearts > 0)
    v.summary += ". At its heart, air that a raw stock holds and no removal clears without cutting the design, "
                 "which would then have to be made again: " + heart;
  return v;
}

Verdict check_manufacturability(const PlanningProblem& p, const std::vector<AtomMeasures>& measures,
                                const Lattice& lattice) {
  Verdict v;
  int additive = 0, subtractive = 0, starts = 0;
  for (const PrimitiveSpec& prim : p.primitives) {
    if (prim.mode == Mode::Additive) {
      ++additive;
      starts += prim.raw_stock;
    } else {
      ++subtractive;
    }
  }
  // A stock followed by removals is the subtractive-only process.
  v.modality = subtractive == 0                          ? Modality::AdditiveOnly
               : additive > 0 && additive == starts      ? Modality::SubtractiveOnly
                                                         : Modality::Hybrid;
  for (int a = 0; a < int(measures.size()); ++a) {
    const AtomMeasures& m = measures[std::size_t(a)];
    if (m.atom_class != AtomClass::Violating) continue;
    ViolatingAtom va = located_atom(p, m, a, lattice);
    va.description = describe(p, va);
    v.violations.push_back(std::move(va));
  }
  std::sort(v.violations.begin(), v.violations.end(),
            [](const ViolatingAtom& x, const ViolatingAtom& y) { return x.volume > y.volume; });
  if (!v.violations.empty()) {
    v.outcome = Verdict::Outcome::NotManufacturable;
    v.decided_without_search = true;
    v.summary = "not manufacturable within tolerance: " + std::to_string(v.violations.size()) +
                (v.violations.size() == 1 ? " atom straddles the design" : " atoms straddle the design");
    return v;
  }
  switch (v.modality) {
    case Modality::AdditiveOnly:
      v.decided_without_search = true;
      v.outcome = additive_only_possible(p) ? Verdict::Outcome::Manufacturable : Verdict::Outcome::NotManufacturable;
      v.summary = v.manufacturable() ? "manufacturable by deposition alone"
                                   : "not manufacturable: the depositions cannot cover the design without overfill";
      return v;
    case Modality::SubtractiveOnly:
      v.decided_without_search = true;
      v.outcome = subtractive_only_possible(p) ? Verdict::Outcome::Manufacturable : Verdict::Outcome::NotManufacturable;
      v.summary = v.manufacturable() ? "manufacturable from stock by removal alone"
                                   : "not manufacturable: no stock and removals leave the design";
      return v;
    case Modality::Hybrid:
      for (const auto& [a, why] : atoms_no_deposit_makes(p, measures)) {
        const AtomMeasures& m = measures[std::size_t(a)];
        ViolatingAtom va = located_atom(p, m, a, lattice);
        va.description = "a " + format("%.3g", m.volume) + " mm\u00B3 region of the design around " +
                         format("(%.1f, %.1f, %.1f)", m.centroid.x, m.centroid.y, m.centroid.z) + " mm: " + why;
        v.violations.push_back(std::move(va));
      }
      if (!v.violations.empty()) {
        std::sort(v.violations.begin(), v.violations.end(),
                  [](const ViolatingAtom& x, const ViolatingAtom& y) { return x.volume > y.volume; });
        v.outcome = Verdict::Outcome::NotManufacturable;
        v.decided_without_search = true;
        v.summary = "not manufacturable: " + std::to_string(v.violations.size()) +
                    (v.violations.size() == 1 ? " atom" : " atoms") +
                    " of the design no deposit makes without material outside it that only removals cutting into "
                    "the atom clear";
        return v;
      }
      v.outcome = Verdict::Outcome::Manufacturable;  // not ruled out: the search decides
      v.summary = "no atom straddles the design; hybrid plans are searched";
      return v;
  }
  return v;
}

const char* to_string(Verdict::Outcome outcome) {
  switch (outcome) {
    case Verdict::Outcome::Manufacturable: return "manufacturable";
    case Verdict::Outcome::NotManufacturable: return "not-manufacturable";
    case Verdict::Outcome::Undecided: return "undecided";
  }
  return "?";
}

}  // namespace hybridctl::planner
