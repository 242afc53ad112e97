#include "planner/pipeline/plan_report.hpp"

#include <unistd.h>

#include <cmath>
#include <algorithm>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <tbb/parallel_for.h>
#include <sstream>

#include "common/number_text.hpp"
#include "common/error.hpp"
#include "geometry/vdb_file.hpp"
#include "plan/plan_machine.hpp"

namespace hybridctl::planner {

using plan::kPlanFormatVersion;
using plan::machine_text_hash;
using plan::path_from_plan_directory;

namespace {

using nlohmann::json;

json vec(const geometry::Vec3& v) { return json::array({v.x, v.y, v.z}); }
json ivec(const geometry::Index3& v) { return json::array({v.x, v.y, v.z}); }
json box_json(const geometry::Box3& b) { return {{"min", vec(b.min)}, {"max", vec(b.max)}}; }

std::string mode_name(Mode m) { return std::string(config::to_string(m)); }

const char* modality_name(Modality m) {
  switch (m) {
    case Modality::AdditiveOnly: return "additive-only";
    case Modality::SubtractiveOnly: return "subtractive-only";
    case Modality::Hybrid: return "hybrid";
  }
  return "?";
}

json atom_ids(const AtomSet& set, int atoms) {
  json ids = json::array();
  for (int a = 0; a < atoms; ++a)
    if (set.test(a)) ids.push_back(a);
  return ids;
}

std::string fixed(double v, int digits) { return fixed_number(v, digits); }

// A distance that may be infinite (nothing made) and a place that may be absent: null.
json distance_json(double mm) { return std::isfinite(mm) ? json(mm) : json(nullptr); }
json place_json(const std::optional<geometry::Vec3>& at) { return at ? vec(*at) : json(nullptr); }

// What in the tolerance zone an atom holds (planner/atoms/tolerance_zone.hpp), which decides its class.
json class_reasons(bool core, bool thin_feature, bool beyond_hull, bool thin_gap) {
  json r = json::array();
  if (core) r.push_back("core");
  if (thin_feature) r.push_back("thin-feature");
  if (beyond_hull) r.push_back("beyond-hull");
  if (thin_gap) r.push_back("thin-gap");
  return r;
}

json exact_place_json(const plan::ExactPlace& p) {
  return {{"mm", p.mm},
          {"at", place_json(p.at)},
          {"action", p.action},
          {"line", p.line},
          {"as_deposited", p.as_deposited},
          {"at_least", p.at_least}};
}

// plan.json's `deviation.exact` (docs/plan-format.md): null when not verified exactly.
json exact_json(const std::optional<plan::ExactDeviation>& e) {
  if (!e) return nullptr;
  return {{"max_excess_mm", e->excess.mm},
          {"max_gouge_mm", e->gouge.mm},
          {"excess", exact_place_json(e->excess)},
          {"gouge", exact_place_json(e->gouge)},
          {"within_share", e->within_share},
          {"within_tolerance", e->within_tolerance()},
          {"tolerance", e->tolerance},
          {"spacing", e->spacing},
          {"samples", e->samples}};
}

json deviation_json(const plan::Deviation& d, const std::optional<plan::ExactDeviation>& exact) {
  return {{"over_volume", d.over_volume},
          {"under_volume", d.under_volume},
          {"worst_over", d.worst_over},
          {"worst_under", d.worst_under},
          {"worst_distance", d.worst_distance},
          {"worst_out", distance_json(d.worst_out)},
          {"worst_out_at", place_json(d.worst_out_at)},
          {"worst_missing", distance_json(d.worst_missing)},
          {"worst_missing_at", place_json(d.worst_missing_at)},
          {"within_tolerance", d.within_tolerance},
          {"exact", exact_json(exact)}};
}

// plan.json's `optimality` of the plan at index k (docs/plan-format.md).
// A cost in the objective's units: "0.2321" (cost factors), "113.2 min", "245.10 EUR".
std::string cost_text(const PlanningResult& r, double cost) {
  if (r.objective == config::Objective::Time) return fixed(cost, 1) + " min";
  if (r.objective == config::Objective::Money) return money_text(cost, r.currency);
  return fixed(cost, 4);
}

std::string objective_text(const PlanningResult& r) {
  switch (r.objective) {
    case config::Objective::Time: return "time: plans cost their minutes of machine time (docs/costs.md)";
    case config::Objective::Money:
      return "money: machine time at its rate, material and tool wear, in " + r.currency + " (docs/costs.md)";
    case config::Objective::CostFactor: break;
  }
  return "cost-factor: the machine file's dimensionless cost_per_mm3 and fixed_costs, over the bounding box's "
         "volume; estimates from the rates in the costs section or their defaults (docs/costs.md)";
}

// A plan's program's cycle time in minutes, changes included; null when not known.
json toolpath_total(const PlanningResult& r, std::size_t k) {
  if (k >= r.cycle_times.size() || !r.cycle_times[k]) return nullptr;
  return r.cycle_times[k]->seconds / 60.0;
}

json cycle_time_json(const PlanningResult& r, std::size_t k) {
  if (k >= r.cycle_times.size() || !r.cycle_times[k]) return nullptr;
  return {{"seconds", r.cycle_times[k]->seconds}, {"includes", r.cycle_times[k]->text}};
}

// A plan's rank in the search's order (0 = first): its place unless the toolpaths re-ranked.
std::size_t search_rank(const PlanningResult& r, std::size_t k) { return k < r.search_rank.size() ? r.search_rank[k] : k; }

json estimate_json(const Estimate& e) { return {{"minutes", e.minutes}, {"money", e.money}}; }

std::string optimality(const Plan& plan, std::size_t k) {
  if (plan.exact) return k == 0 ? "proven-optimal" : "proven-rank";
  return std::isfinite(plan.gap) ? "gap" : "unknown";
}

// The same for people: "proven optimal", "proven 2nd cheapest (+1.2 %)", "within 3.1 % of
// optimal (proven)".
std::string optimality_text(const Plan& plan, std::size_t k) {
  const std::string percent = fixed(100 * plan.gap, plan.gap < 0.1 ? 2 : 1) + " %";
  if (plan.exact && k == 0) return "proven optimal";
  if (plan.exact) return "proven rank " + std::to_string(k + 1) + " (" + percent + " above the optimum)";
  if (!std::isfinite(plan.gap)) return "no proven bound on its distance from the optimum";
  return "within " + percent + " of optimal (proven)";
}

json reason_json(const plan::RejectionReason& reason) {
  json j = {{"kind", reason.kind}};
  if (reason.action > 0) j["action"] = reason.action;
  if (reason.line > 0) j["line"] = reason.line;
  if (!reason.message.empty()) j["message"] = reason.message;
  if (reason.where) j["where"] = vec(*reason.where);
  return j;
}

// Candidates that validation by execution turned down, with their located reasons.
json rejected_json(const PlanningResult& r) {
  json rejected = json::array();
  for (const RejectedPlan& candidate : r.rejected) {
    json steps = json::array();
    for (std::size_t s = 0; s < candidate.plan.steps.size(); ++s) {
      const PlanStep& step = candidate.plan.steps[s];
      const Primitive& prim = r.primitives[std::size_t(step.primitive)];
      steps.push_back({{"step", s + 1},
                       {"primitive", prim.name},
                       {"mode", mode_name(prim.mode)},
                       {"volume", step.volume},
                       {"cost", step.cost}});
    }
    json reasons = json::array();
    for (const plan::RejectionReason& reason : candidate.reasons) reasons.push_back(reason_json(reason));
    rejected.push_back({{"expression", expression(r.problem, candidate.plan)},
                        {"cost", candidate.plan.cost},
                        {"steps", steps},
                        {"reasons", reasons}});
  }
  return rejected;
}

// The raw stocks proven before the search to start no plan: why the search never starts
// from them (planner/search/start_proofs.hpp).
std::string stock_starts_text(const PlanningResult& r) {
  std::string out;
  for (const StartProof& s : r.stock_starts) {
    if (s.proof.outcome != CoreProof::Outcome::Proven) continue;
    const Primitive& p = r.primitives[std::size_t(s.primitive)];
    out += "stocks      no plan starts from " + p.name + " (" + p.label + "): no sequence after it gets " +
           std::to_string(s.proof.core.size()) + " atom" + (s.proof.core.size() == 1 ? "" : "s") +
           " right together (proven over " + std::to_string(s.proof.states) + " states)\n";
  }
  return out;
}

json stock_starts_json(const PlanningResult& r) {
  json out = json::array();
  for (const StartProof& s : r.stock_starts) {
    const CoreProof::Outcome o = s.proof.outcome;
    out.push_back({{"primitive", r.primitives[std::size_t(s.primitive)].name},
                   {"starts_a_plan", o == CoreProof::Outcome::Proven ? json(false)
                                     : o == CoreProof::Outcome::Feasible ? json(true)
                                                                          : json(nullptr)},
                   {"atoms", o == CoreProof::Outcome::Proven ? json(s.proof.core) : json::array()}});
  }
  return out;
}

// The rule of faces left as deposited: per deposit held to it, why and on how many atoms;
// the faces executed candidates showed; the plans passed over for it.
json faces_json(const PlanningResult& r) {
  json deposits = json::array();
  for (std::size_t i = 0; i < r.faces.tight.size(); ++i) {
    if (r.faces.why[i].empty()) continue;
    std::size_t atoms = 0;
    for (const std::uint64_t w : r.faces.tight[i].words()) atoms += std::size_t(__builtin_popcountll(w));
    deposits.push_back({{"primitive", r.primitives[i].name},
                        {"atoms", atoms},
                        {"learned_atoms", r.faces.learned_atoms[i].size()},
                        {"why", r.faces.why[i]}});
  }
  json learned = json::array();
  for (const DepositedFace& f : r.faces.learned)
    learned.push_back({{"primitive", r.primitives[std::size_t(f.primitive)].name}, {"at", {f.at.x, f.at.y, f.at.z}}, {"mm", f.mm}});
  return {{"deposits", deposits},
          {"learned", learned},
          {"passed_over", r.faces.passed_over},
          {"first", r.faces.first_passed.empty() ? json(nullptr) : json(r.faces.first_passed)}};
}

// The verdict's atoms as `plan` lists them: at most ten; of a proof's atoms, those that
// must be made or left empty when there are any: the band's only carry or block the
// others, a voxel layer along a face or an edge rather than a feature of the part
// (plan.json has them all).
std::string violations_text(const PlanningResult& r) {
  std::ostringstream os;
  const bool proof = r.core_proof.outcome == CoreProof::Outcome::Proven && !r.verdict.manufacturable();
  std::vector<const ViolatingAtom*> listed;
  std::size_t band = 0;
  for (const ViolatingAtom& v : r.verdict.violations) {
    const std::size_t a = std::size_t(v.atom);
    const bool in_band = proof && a < r.problem.atoms.size() && !r.problem.atoms[a].must_in && !r.problem.atoms[a].must_out;
    band += in_band;
    if (!in_band) listed.push_back(&v);
  }
  if (listed.empty()) {
    band = 0;
    for (const ViolatingAtom& v : r.verdict.violations) listed.push_back(&v);
  }
  const std::size_t shown = std::min<std::size_t>(listed.size(), 10);
  for (std::size_t i = 0; i < shown; ++i) os << "  - " << listed[i]->description << "\n";
  if (r.verdict.violations.size() > shown)
    os << "  ... and " << r.verdict.violations.size() - shown << " more in plan.json"
       << (band > 0 ? " (" + std::to_string(band) + " of them in the planning band, carrying or blocking the others)" : "")
       << "\n";
  return os.str();
}

// One line per candidate that failed when executed, with its first reasons.
std::string rejected_summary(const PlanningResult& r) {
  std::ostringstream os;
  os << "validated   every plan offered was exported and executed from the raw stock; " << r.rejected.size()
     << " candidate" << (r.rejected.size() == 1 ? "" : "s") << " rejected";
  // How many failed first for which reason: what stands between the part and a plan.
  std::vector<std::pair<std::string, int>> by_kind;
  for (const RejectedPlan& candidate : r.rejected) {
    const std::string kind = candidate.reasons.empty() ? std::string("no reason") : candidate.reasons.front().kind;
    auto it = std::find_if(by_kind.begin(), by_kind.end(), [&](const auto& k) { return k.first == kind; });
    if (it == by_kind.end())
      by_kind.emplace_back(kind, 1);
    else
      ++it->second;
  }
  std::stable_sort(by_kind.begin(), by_kind.end(), [](const auto& a, const auto& b) { return a.second > b.second; });
  for (std::size_t i = 0; i < by_kind.size(); ++i)
    os << (i == 0 ? " (first reasons: " : ", ") << by_kind[i].first << " " << by_kind[i].second
       << (i + 1 == by_kind.size() ? ")" : "");
  const std::int64_t repeating = r.search.known_to_fail - r.faces.passed_over;
  if (repeating > 0)
    os << "; " << repeating << " more passed over unexecuted: they begin with the actions a rejected one failed in, or repeat a "
                                 "failure against the STL executed before";
  os << "\n";
  if (!r.learned.empty()) os << "learned     " << learned_text(r) << "\n";
  // One line each for the cheapest: the expression, the cost and the first reason, short; a
  // reason told in full once (candidates that begin the same way fail the same way). The
  // rest are counted; plan.json has them all.
  constexpr std::size_t kShown = 20;
  std::vector<std::string> told;
  for (std::size_t n = 0; n < r.rejected.size(); ++n) {
    const RejectedPlan& candidate = r.rejected[n];
    if (n == kShown) {
      os << "  ... and " << r.rejected.size() - kShown << " more candidates in plan.json\n";
      break;
    }
    os << "  x " << expression(r.problem, candidate.plan) << "  cost " << cost_text(r, candidate.plan.cost);
    if (candidate.reasons.empty()) {
      os << "\n";
      continue;
    }
    const plan::RejectionReason& first = candidate.reasons.front();
    const std::string text = describe(first);
    const bool again = std::find(told.begin(), told.end(), text) != told.end();
    os << ": " << first.kind;
    if (again)
      os << " (as above" << (first.action > 0 ? ", action " + std::to_string(first.action) : std::string()) << ")";
    else
      os << ": " << text;
    if (candidate.reasons.size() > 1) os << "; " << candidate.reasons.size() - 1 << " more in plan.json";
    os << "\n";
    if (!again) told.push_back(text);
  }
  return os.str();
}

}  // namespace

std::string primitive_capability(const Primitive& p, const std::filesystem::path& directory) {
  return p.kind == PrimitiveKind::File || p.from_file ? path_from_plan_directory(p.capability, directory) : p.capability;
}

namespace {

// The offered plans, best first, each with its actions.
json plans_json(const PlanningResult& r) {
  json plans = json::array();
  for (std::size_t k = 0; k < r.plans.size(); ++k) {
    const Plan& plan = r.plans[k];
    const PlanEstimate estimate = k < r.estimates.size() ? r.estimates[k] : PlanEstimate{};
    json actions = json::array();
    for (std::size_t s = 0; s < plan.steps.size(); ++s) {
      const PlanStep& step = plan.steps[s];
      const Primitive& prim = r.primitives[std::size_t(step.primitive)];
      const Estimate e = s < estimate.steps.size() ? estimate.steps[s] : Estimate{};
      actions.push_back({{"step", s + 1},
                         {"primitive", prim.name},
                         {"mode", mode_name(prim.mode)},
                         {"volume", step.volume},
                         {"cost", step.cost},
                         {"estimate", estimate_json(e)},
                         {"toolpath_minutes", k < r.toolpath_minutes.size() && s < r.toolpath_minutes[k].size()
                                                  ? json(r.toolpath_minutes[k][s])
                                                  : json(nullptr)},
                         {"region_atoms", atom_ids(step_region(r, plan, s), r.atoms.atom_count())}});
    }
    const plan::Deviation& d = r.deviations[k];
    plans.push_back({{"rank", k + 1},
                     {"expression", expression(r.problem, plan)},
                     {"cost", plan.cost},
                     {"estimate", estimate_json(estimate.total)},
                     {"toolpath_minutes", toolpath_total(r, k)},
                     {"cycle_time", cycle_time_json(r, k)},
                     {"optimality", optimality(plan, search_rank(r, k))},
                     {"search_rank", search_rank(r, k) + 1},
                     {"found_by", plan.exact      ? "exact-search"
                                 : plan.built  ? "built-step-by-step"
                                 : plan.replayed ? "proof-replay"
                                                 : "weighted-search"},
                     {"toolpath_cost", k < r.toolpath_costs.size() ? json(r.toolpath_costs[k]) : json(nullptr)},
                     {"gap", std::isfinite(plan.gap) ? json(plan.gap) : json(nullptr)},
                     {"file", "plans/plan-" + std::to_string(k + 1) + ".vdb"},
                     {"final_atoms", atom_ids(plan.final_state, r.atoms.atom_count())},
                     {"deviation", deviation_json(d, k < r.exact_deviations.size() ? r.exact_deviations[k] : std::nullopt)},
                     {"actions", actions}});
  }
  return plans;
}

// The inside corners a refusal rests on (plan-format.md, "Verdict").
json corners_json(const PlanningResult& r) {
  json corners = json::array();
  for (const plan::UnreachedCorner& c : r.unreached_corners)
    corners.push_back({{"from", vec(c.from)}, {"to", vec(c.to)}, {"air_angle_deg", c.air_angle},
                       {"nearest_mm", c.nearest}, {"nearest_by", c.nearest_by}});
  return corners;
}

}  // namespace

std::string plan_json(const PlanningResult& r, const ReportSources& src, const std::filesystem::path& directory) {
  json doc;
  doc["format"] = "hybridctl-plan";
  doc["version"] = kPlanFormatVersion;
  doc["part"] = path_from_plan_directory(src.part_path, directory);
  doc["machine"] = {{"name", src.machine_name},
                    {"file", path_from_plan_directory(src.machine_path, directory)},
                    {"hash", machine_text_hash(src.machine_text)},
                    {"yaml", src.machine_text}};
  doc["grid"] = {{"voxel_size", r.lattice.voxel_size},
                 {"origin", vec(r.lattice.origin)},
                 {"domain", {{"lo", ivec(r.domain.lo)}, {"hi", ivec(r.domain.hi)}}}};
  doc["design"] = {{"file", "design.vdb"},
                   {"volume", r.design_volume},
                   {"bounding_box", box_json(r.design.bounding_box_mm())}};
  doc["tolerance"] = r.tolerance;
  doc["band"] = r.band;
  doc["sliver_threshold"] = r.sliver_threshold;
  doc["objective"] = std::string(config::to_string(r.objective));
  doc["currency"] = r.currency;
  doc["cost_normaliser"] = r.problem.normaliser;
  doc["fixed_costs"] = {{"tool_change", r.problem.fixed.tool_change},
                        {"setup_change", r.problem.fixed.setup_change},
                        {"mode_switch", r.problem.fixed.mode_switch},
                        {"refixture", r.problem.fixed.refixture}};
  doc["max_uses"] = r.problem.max_uses;

  json prims = json::array();
  for (const Primitive& p : r.primitives) {
    json j = {{"name", p.name},       {"label", p.label},       {"kind", std::string(config::to_string(p.kind))},
              {"mode", mode_name(p.mode)}, {"capability", primitive_capability(p, directory)}, {"setup", p.setup},
              {"cost_per_mm3", p.cost_per_mm3}, {"volume", p.region.volume()},
              {"file", "primitives/" + p.name + ".vdb"}};
    if (p.tool_number) j["tool_number"] = p.tool_number;
    prims.push_back(j);
  }
  doc["primitives"] = prims;

  const int n = int(r.primitives.size());
  json atoms = json::array();
  for (int a = 0; a < int(r.measures.size()); ++a) {
    const AtomMeasures& m = r.measures[std::size_t(a)];
    atoms.push_back({{"id", a},
                     {"code", m.code.bits(n)},
                     {"volume", m.volume},
                     {"volume_in_design", m.volume_in_design},
                     {"class", to_string(m.atom_class)},
                     {"reasons", class_reasons(m.voxels_in_core > 0, m.thin_feature, m.voxels_beyond_hull > 0, m.thin_gap)},
                     {"sliver", m.sliver},
                     {"bounding_box", box_json(r.lattice.extent(m.bounding_box))},
                     {"centroid", vec(m.centroid)}});
  }
  doc["atoms"] = atoms;

  json violations = json::array();
  for (const ViolatingAtom& v : r.verdict.violations) {
    json in = json::array();
    for (int i : v.primitives) in.push_back(r.primitives[std::size_t(i)].name);
    violations.push_back({{"atom", v.atom},
                          {"code", v.code},
                          {"primitives", in},
                          {"volume", v.volume},
                          {"volume_in_design", v.volume_in_design},
                          {"bounding_box", box_json(v.bounds)},
                          {"centroid", vec(v.centroid)},
                          {"reasons", class_reasons(v.holds_core, v.holds_thin_feature, v.beyond_hull, v.holds_thin_gap)},
                          {"description", v.description}});
  }
  doc["verdict"] = {{"outcome", to_string(r.verdict.outcome)},
                    {"manufacturable", r.verdict.manufacturable()},
                    {"decided_without_search", r.verdict.decided_without_search},
                    {"modality", modality_name(r.verdict.modality)},
                    {"summary", r.verdict.summary},
                    {"in_shop_words", r.in_shop_words},
                    {"violations", violations},
                    {"unreached_corners", corners_json(r)}};
  json unsplit = json::array();
  for (const FineGraining::Unsplit& u : r.fine_graining.unsplit) unsplit.push_back({{"atom", u.atom}, {"why", u.why}});
  doc["fine_graining"] = {{"rounds", r.fine_graining.rounds},
                          {"added", r.fine_graining.added},
                          {"capped", r.fine_graining.capped},
                          {"unsplit", unsplit}};
  doc["search"] = {{"expanded", r.search.expanded},
                   {"generated", r.search.generated},
                   {"exhausted", r.search.exhausted},
                   {"limit_reached", r.search.limit_reached},
                   {"known_to_fail", r.search.known_to_fail},
                   {"faces_left_as_deposited", faces_json(r)},
                   {"weight", r.search.weight},
                   {"lower_bound", r.search.lower_bound},
                   {"seconds", r.search.seconds},
                   {"rounds", r.search_rounds},
                   {"replays", r.replay_rounds},
                   {"stock_starts", stock_starts_json(r)}};

  const json plans = plans_json(r);
  doc["plans"] = plans;
  doc["ranked_by_toolpaths"] = r.ranked_by_toolpaths;
  doc["estimates_off"] = r.estimates_off;
  doc["validated"] = r.validated;
  doc["rejected"] = rejected_json(r);
  json learned = json::array();
  for (const Shortfall& s : r.learned) {
    const AtomMeasures& m = r.measures[std::size_t(s.atom)];
    learned.push_back({{"primitive", r.problem.primitives[std::size_t(s.primitive)].name},
                       {"atom", s.atom},
                       {"volume_mm3", s.volume},
                       {"centroid", {m.centroid.x, m.centroid.y, m.centroid.z}},
                       {"kind", s.spill ? "spills_onto" : "falls_short"}});
  }
  doc["learned"] = learned;
  json timings = json::object();
  for (const auto& [phase, seconds] : r.timings) timings[phase] = seconds;
  doc["timings_s"] = timings;
  return doc.dump(2) + "\n";
}

void write_plan_directory(const PlanningResult& r, const ReportSources& src, const std::filesystem::path& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::exists(dir, ec)) {
    if (!fs::is_directory(dir, ec)) throw InputError(dir.string() + ": exists and is not a directory; expected a new or plan output directory");
    if (!fs::is_empty(dir, ec) && !fs::exists(dir / "plan.json", ec)) {
      throw InputError(dir.string() + ": not empty and holds no plan.json; refusing to replace it (expected a new, empty or earlier plan directory)");
    }
  }
  const fs::path parent = dir.parent_path().empty() ? fs::path(".") : dir.parent_path();
  // Like mkdir -p: the directories above DIR are made when missing.
  fs::create_directories(parent, ec);
  if (!fs::is_directory(parent, ec))
    throw InputError(dir.string() + ": cannot write: cannot make the directory " + parent.string() +
                     (ec ? ": " + ec.message() : std::string()));
  // Everything goes into a fresh sibling directory that replaces DIR only when complete.
  const fs::path staging = parent / ("." + dir.filename().string() + ".tmp-" + std::to_string(::getpid()));
  fs::remove_all(staging, ec);
  try {
    fs::create_directories(staging / "primitives");
    fs::create_directories(staging / "plans");
    // Tens of grids on the B-axis machine, each compressed on its own: written side by side.
    const std::size_t grids = 1 + r.primitives.size() + r.plans.size();
    tbb::parallel_for(std::size_t(0), grids, [&](std::size_t i) {
      if (i == 0) {
        geometry::write_vdb(r.design, staging / "design.vdb", "design");
      } else if (i <= r.primitives.size()) {
        const Primitive& p = r.primitives[i - 1];
        geometry::write_vdb(p.region, staging / "primitives" / (p.name + ".vdb"), p.name);
      } else {
        const std::size_t k = i - 1 - r.primitives.size();
        geometry::write_vdb(plan_outcome(r, r.plans[k]), staging / "plans" / ("plan-" + std::to_string(k + 1) + ".vdb"),
                            "plan-" + std::to_string(k + 1));
      }
    });
    // The design's real surface goes with the plan: exact verification (export, run,
    // dry-run) reads it wherever the directory is copied to.
    if (!src.part_path.empty() && fs::is_regular_file(src.part_path, ec))
      fs::copy_file(src.part_path, staging / plan::kDesignStl);
    std::ofstream out(staging / "plan.json");
    out << plan_json(r, src, dir);
    if (!out.flush()) throw InputError((staging / "plan.json").string() + ": cannot write");
    out.close();
    const fs::path old = parent / ("." + dir.filename().string() + ".old-" + std::to_string(::getpid()));
    if (fs::exists(dir)) fs::rename(dir, old);
    fs::rename(staging, dir);
    fs::remove_all(old, ec);
  } catch (const fs::filesystem_error& e) {
    fs::remove_all(staging, ec);
    throw InputError(dir.string() + ": cannot write: " + e.code().message());
  } catch (...) {
    fs::remove_all(staging, ec);
    throw;
  }
}

std::string plan_summary(const PlanningResult& r, const ReportSources& src, bool verbose) {
  std::ostringstream os;
  const geometry::IndexBox b = r.design.bounding_box();
  os << "design      " << src.part_path << ": " << fixed(r.design_volume, 1) << " mm\u00B3, " << (b.hi.x - b.lo.x) << " x "
     << (b.hi.y - b.lo.y) << " x " << (b.hi.z - b.lo.z) << " voxels of " << r.lattice.voxel_size << " mm\n";
  os << "machine     " << src.machine_name << " (" << src.machine_path << "), tolerance " << r.tolerance << " mm"
     << (r.band > r.tolerance ? " on the STL's surface (the voxels are judged within a band of " + shortest_number(r.band) + " mm)" : "")
     << "\n";
  os << "objective   " << objective_text(r) << "\n";
  os << "primitives  " << r.primitives.size() << "\n";
  for (const Primitive& p : r.primitives) {
    char line[256];
    std::snprintf(line, sizeof line, "  %-4s %-58s %-11s %12.1f mm\u00B3\n", p.name.c_str(), p.label.c_str(),
                  p.mode == Mode::Additive ? "additive" : "subtractive", p.region.volume());
    os << line;
  }
  int counts[4] = {0, 0, 0, 0}, slivers = 0;
  for (const AtomMeasures& m : r.measures) {
    ++counts[int(m.atom_class)];
    slivers += m.sliver;
  }
  os << "atoms       " << r.measures.size() << ": " << counts[int(AtomClass::MustIn)] << " must-in, "
     << counts[int(AtomClass::MustOut)] << " must-out, " << counts[int(AtomClass::Free)] << " free (" << slivers
     << " slivers), " << counts[int(AtomClass::Violating)] << " violating\n";
  if (r.fine_graining.added > 0)
    os << "fine-grain  " << r.fine_graining.added << " primitive" << (r.fine_graining.added == 1 ? "" : "s")
       << " restricted to the neighbourhood of atoms that straddled the design, in " << r.fine_graining.rounds
       << " round" << (r.fine_graining.rounds == 1 ? "" : "s")
       << (r.fine_graining.capped ? " (stopped at the cap of " + std::to_string(kMaxFineGrainedPrimitives) + ")" : "")
       << "\n";
  // In shop words where they can be said; the proof in atoms behind --verbose.
  const bool in_words = !verbose && !r.in_shop_words.empty() && r.verdict.outcome != Verdict::Outcome::Manufacturable;
  os << "verdict     "
     << (r.verdict.outcome == Verdict::Outcome::Manufacturable  ? "manufacturable"
         : r.verdict.outcome == Verdict::Outcome::Undecided     ? "UNDECIDED"
                                                                : "NOT manufacturable")
     << (in_words ? " (in words below; the proof in atoms and regions: plan.json's verdict, or --verbose)"
                  : ": " + r.verdict.summary)
     << "\n";
  for (std::size_t i = 0; i < r.in_shop_words.size(); ++i)
    os << (i == 0 ? "in words    " : "            ") << r.in_shop_words[i] << "\n";
  if (!in_words) os << violations_text(r);
  os << stock_starts_text(r);
  if (r.validated) os << rejected_summary(r);
  if (r.faces.passed_over > 0)
    os << "faces       " << r.faces.passed_over << " plan" << (r.faces.passed_over == 1 ? "" : "s")
       << " the search found passed over unexecuted: each leaves a face as deposited that its deposit may not leave "
          "so (docs/search.md); the first: "
       << r.faces.first_passed << "\n";
  if (!r.plans.empty()) {
    os << "plans       " << r.plans.size() << " (A*: " << r.search.expanded << " states expanded in "
       << fixed(r.search.seconds, 2) << " s";
    const bool built = std::any_of(r.plans.begin(), r.plans.end(), [](const Plan& p) { return p.built; });
    const bool replayed = std::any_of(r.plans.begin(), r.plans.end(), [](const Plan& p) { return p.replayed; });
    if (r.search.weight > 1 || built || replayed) {
      os << "; the exact search hit its limit, so plans it did not prove come from ";
      std::vector<std::string> sources;
      std::ostringstream weight;
      weight << r.search.weight;
      if (r.search.weight > 1) sources.push_back("weighted A* (w = " + weight.str() + ")");
      if (replayed) sources.push_back("the proofs' replays (plans they found checking that one exists)");
      if (built) sources.push_back("plans built step by step (deposit the missing design, then mill what lies outside it)");
      for (std::size_t i = 0; i < sources.size(); ++i) os << (i ? " and " : "") << sources[i];
      os << " with a proven gap against the lower bound " << fixed(r.search.lower_bound, 4);
    }
    os << ")\n";
    if (r.ranked_by_toolpaths)
      os << "ranked      by the toolpaths' cycle times: " << r.estimates_off
         << " actions' estimates are more than 25 % off their toolpaths' (docs/costs.md)\n";
    else if (r.estimates_off > 0)
      os << "estimates   " << r.estimates_off
         << " actions' estimates are more than 25 % off their toolpaths' cycle times; the ranking stands, as cost "
            "factors are not times (--objective time or money ranks by the toolpaths, docs/costs.md)\n";
    for (std::size_t k = 0; k < r.plans.size(); ++k) {
      const Plan& plan = r.plans[k];
      const plan::Deviation& d = r.deviations[k];
      const PlanEstimate estimate = k < r.estimates.size() ? r.estimates[k] : PlanEstimate{};
      os << "  " << (k + 1) << ". " << expression(r.problem, plan) << "  cost " << cost_text(r, plan.cost) << ", "
         << optimality_text(plan, search_rank(r, k));
      if (k < r.toolpath_costs.size())
        os << " by the estimate; " << cost_text(r, r.toolpath_costs[k]) << " with the toolpaths' times";
      os << "\n";
      os << "     estimate: " << duration_text(estimate.total.minutes) << " of machine time, "
         << money_text(estimate.total.money, r.currency);
      os << " (volumes at the rates, changes as the search counts them)\n";
      if (k < r.cycle_times.size() && r.cycle_times[k])
        os << "     cycle time: " << r.cycle_times[k]->text << " (its program, as export writes it)\n";
      os << "     deviation: " << plan::deviation_text(d, r.band) << " (voxels)\n";
      if (k < r.exact_deviations.size() && r.exact_deviations[k])
        os << "     exact:     " << plan::exact_deviation_text(*r.exact_deviations[k]) << "\n";
      for (std::size_t s = 0; s < plan.steps.size(); ++s) {
        const PlanStep& st = plan.steps[s];
        const Primitive& p = r.primitives[std::size_t(st.primitive)];
        const Estimate e = s < estimate.steps.size() ? estimate.steps[s] : Estimate{};
        std::string toolpath;
        if (k < r.toolpath_minutes.size() && s < r.toolpath_minutes[k].size() && p.kind != PrimitiveKind::RawStock)
          toolpath = "; motion " + format_duration(r.toolpath_minutes[k][s] * 60.0);
        char line[360];
        std::snprintf(line, sizeof line, "     %zu) %-4s %-58s %s %10.1f mm\u00B3  cost %s  (%s, %s%s)\n", s + 1,
                      p.name.c_str(), p.label.c_str(), p.mode == Mode::Additive ? "deposit" : "remove ", st.volume,
                      cost_text(r, st.cost).c_str(), duration_text(e.minutes).c_str(),
                      money_text(e.money, r.currency).c_str(), toolpath.c_str());
        os << line;
      }
    }
  }
  return os.str();
}

}  // namespace hybridctl::planner

namespace hybridctl::planner {

plan::PlanFile to_plan_file(const PlanningResult& r, const ReportSources& sources, const std::filesystem::path& directory) {
  plan::PlanFile f;
  f.directory = directory;
  f.part = plan::path_from_plan_directory(sources.part_path, directory);
  f.machine_name = sources.machine_name;
  f.machine_file = plan::path_from_plan_directory(sources.machine_path, directory);
  f.machine_yaml = sources.machine_text;
  f.machine_hash = plan::machine_text_hash(sources.machine_text);
  f.lattice = r.lattice;
  f.domain = r.domain;
  f.tolerance = r.tolerance;
  f.design_mesh = r.design_mesh;
  f.design = plan::as_read_back(r.design, f.lattice, f.domain);
  for (const Primitive& p : r.primitives) {
    f.primitives.push_back({p.name, p.label, p.kind, p.mode, primitive_capability(p, directory), p.setup, p.tool_number,
                            plan::as_read_back(p.region, f.lattice, f.domain)});
  }
  for (std::size_t k = 0; k < r.plans.size(); ++k) {
    const Plan& plan = r.plans[k];
    plan::PlanFilePlan out{int(k + 1), expression(r.problem, plan), plan.cost, {}};
    for (const PlanStep& step : plan.steps) out.actions.push_back({step.primitive, step.volume, step.cost});
    f.plans.push_back(std::move(out));
  }
  for (const RejectedPlan& rejected : r.rejected) {
    plan::PlanFileRejected out{expression(r.problem, rejected.plan), rejected.plan.cost, {}, rejected.reasons};
    for (const PlanStep& step : rejected.plan.steps) out.actions.push_back({step.primitive, step.volume, step.cost});
    f.rejected.push_back(std::move(out));
  }
  return f;
}

}  // namespace hybridctl::planner
