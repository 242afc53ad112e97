// The search step of plan_part (search_phase.hpp): rounds of search on a problem that
// executed candidates correct, the proofs around it, and the verdict it leaves.

#include "planner/pipeline/search_phase.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <functional>
#include <new>
#include <set>
#include <thread>

#include "common/number_text.hpp"
#include "planner/search/steps.hpp"

namespace hybridctl::planner {
namespace {

// What the rejections of one search taught, before the next search takes it in.
struct Learning {
  std::vector<Shortfall> pending;  // not yet taken out of the problem's primitives
  // Candidates proven by execution: a search started again finds them again, and
  // execution would only repeat itself.
  std::set<std::vector<int>> proven;
};

std::vector<int> primitives_of(const Plan& plan) { return plan.primitives(); }

// The search's accept hook from PlanningOptions::validate: rejected plans are kept with
// their reasons (once each, as a weighted search may find them again), their shortfalls
// wait in `learning` for the next round, and the time the validation takes is counted
// apart from the search's.
std::function<bool(const Plan&)> accept_hook(const PlanningOptions& options, PlanningResult& r, double& seconds,
                                             Learning& learning) {
  if (!options.validate) return {};
  return [&options, &r, &seconds, &learning](const Plan& plan) {
    const std::vector<int> sequence = primitives_of(plan);
    if (learning.proven.count(sequence)) return true;
    const auto same_actions = [&sequence](const RejectedPlan& known) { return primitives_of(known.plan) == sequence; };
    if (std::any_of(r.rejected.begin(), r.rejected.end(), same_actions)) return false;
    const auto start = std::chrono::steady_clock::now();
    CandidateCheck check = options.validate(r, plan);
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (check.reasons.empty()) {
      learning.proven.insert(sequence);
      return true;
    }
    for (const DepositedFace& face : check.faces) learn_face(r.faces, r.problem, r.atoms, r.measures, face);
    for (const Shortfall& s : check.shortfalls) {
      const PrimitiveSpec& prim = r.problem.primitives[std::size_t(s.primitive)];
      const AtomSet& known = s.spill ? prim.atoms : prim.falls_short;
      const bool learned = !known.words().empty() && known.test(s.atom);
      if (!learned && std::find(learning.pending.begin(), learning.pending.end(), s) == learning.pending.end())
        learning.pending.push_back(s);
    }
    r.rejected.push_back({plan, std::move(check.reasons)});
    return false;
  };
}

// Plans that begin with the actions a rejected plan failed in, up to the failing action:
// execution depends only on the actions before (validation/prefix_cache.hpp), so they
// fail the same way, and the search passes over them without executing them. The design's
// core missing after the last deposit is such a failure only for a plan that, like the
// rejected one, only removes after that action.
//
// And plans that leave a face as deposited where the rule of deposited faces forbids it
// (planner/pipeline/deposited_faces.hpp), validated or not: their parts are known to come
// out beyond the tolerance there. And those validation knows to fail unexecuted
// (PlanningOptions::known_failure: a failure against the STL they repeat).
std::function<bool(const Plan&)> known_failure_hook(const PlanningOptions& options, PlanningResult& r) {
  const bool validated = bool(options.validate);
  return [&options, &r, validated](const Plan& plan) {
    if (const std::optional<FaceLeft> left = face_left_as_deposited(r.problem, r.faces, plan)) {
      if (r.faces.passed_over++ == 0) r.faces.first_passed = describe_face_left(r.problem, r.faces, r.measures, plan, *left);
      return true;
    }
    if (!validated) return false;
    const auto only_removes_after = [&](std::size_t k) {
      return std::all_of(plan.steps.begin() + std::ptrdiff_t(k), plan.steps.end(), [&](const PlanStep& s) {
        return r.problem.primitives[std::size_t(s.primitive)].mode == Mode::Subtractive;
      });
    };
    for (const RejectedPlan& known : r.rejected)
      for (const plan::RejectionReason& reason : known.reasons) {
        const std::size_t k = std::size_t(reason.action);
        if (k == 0 || k > plan.steps.size() || k > known.plan.steps.size()) continue;
        if (reason.kind == "missing_material" && !only_removes_after(k)) continue;
        // The part made against the STL depends on every action after the one that made
        // the place: a face left as deposited is the face rule's (above), which knows
        // what finishes it.
        if (reason.kind == "exact_excess" || reason.kind == "exact_gouge") continue;
        if (std::equal(plan.steps.begin(), plan.steps.begin() + std::ptrdiff_t(k), known.plan.steps.begin(),
                       [](const PlanStep& a, const PlanStep& b) { return a.primitive == b.primitive; }))
          return true;
      }
    return options.known_failure && options.known_failure(r, plan);
  };
}

// What the nearest state the exploration reached lacks and holds beyond the design: its
// largest wrong atoms with where they are and what holds them.
std::string nearest_text(const PlanningResult& r, const Reachability& reach) {
  struct Wrong {
    int atom;
    double volume;
  };
  std::vector<Wrong> missing, extra;
  double missing_volume = 0, extra_volume = 0;
  for (std::size_t a = 0; a < r.problem.atoms.size(); ++a) {
    const AtomSpec& spec = r.problem.atoms[a];
    const bool present = reach.nearest.test(int(a));
    if (spec.must_in && !present) missing.push_back({int(a), spec.volume}), missing_volume += spec.volume;
    if (spec.must_out && present) extra.push_back({int(a), spec.volume}), extra_volume += spec.volume;
  }
  const auto largest = [&](std::vector<Wrong>& atoms) {
    const auto big = std::max_element(atoms.begin(), atoms.end(), [](const Wrong& a, const Wrong& b) { return a.volume < b.volume; });
    const AtomMeasures& m = r.measures[std::size_t(big->atom)];
    char where[96];
    std::snprintf(where, sizeof where, "%.3g mm\u00B3 around (%.1f, %.1f, %.1f) mm", m.volume, m.centroid.x, m.centroid.y,
                  m.centroid.z);
    std::string in;
    for (std::size_t i = 0; i < r.problem.primitives.size(); ++i)
      if (r.problem.primitives[i].atoms.test(big->atom)) in += (in.empty() ? "" : ", ") + r.problem.primitives[i].name;
    return std::string(where) + (in.empty() ? ", in no primitive" : ", in " + in);
  };
  std::string s = "lacks " + trimmed_number(missing_volume, 1) + " mm\u00B3 of design in " + std::to_string(missing.size()) +
                  " atoms";
  if (!missing.empty()) s += " (largest: " + largest(missing) + ")";
  s += " and holds " + trimmed_number(extra_volume, 1) + " mm\u00B3 outside it in " + std::to_string(extra.size()) + " atoms";
  if (!extra.empty()) s += " (largest: " + largest(extra) + ")";
  return s;
}

}  // namespace

namespace {

// "N primitives falling short of the model on M atoms (V mm³; largest ...)" for the
// shortfalls, or the spills, learned.
std::string learned_kind_text(const PlanningResult& r, bool spills) {
  std::set<int> primitives;
  double volume = 0;
  int atoms = 0;
  const Shortfall* largest = nullptr;
  for (const Shortfall& s : r.learned) {
    if (s.spill != spills) continue;
    primitives.insert(s.primitive);
    volume += s.volume;
    ++atoms;
    if (!largest || s.volume > largest->volume) largest = &s;
  }
  if (!largest) return {};
  const AtomMeasures& m = r.measures[std::size_t(largest->atom)];
  char where[96];
  std::snprintf(where, sizeof where, "%.3g mm\u00B3 around (%.1f, %.1f, %.1f) mm", m.volume, m.centroid.x, m.centroid.y,
                m.centroid.z);
  return std::to_string(primitives.size()) + " primitive" + (primitives.size() == 1 ? "" : "s") +
         (spills ? " spilling onto " : " falling short of the model on ") + std::to_string(atoms) + " atom" +
         (atoms == 1 ? "" : "s") + (spills ? " outside them" : "") + " (" + trimmed_number(volume, 1) +
         " mm\u00B3; largest " + where + ", by " + r.problem.primitives[std::size_t(largest->primitive)].name + ")";
}

}  // namespace

std::string learned_text(const PlanningResult& r) {
  if (r.learned.empty()) return {};
  const std::string short_of = learned_kind_text(r, false), spilled = learned_kind_text(r, true);
  const std::string how = short_of.empty() ? "added to them" : spilled.empty() ? "taken out of them" : "corrected";
  return "executed candidates showed " + short_of + (short_of.empty() || spilled.empty() ? "" : " and ") + spilled +
         ", " + how + " over " + std::to_string(r.search_rounds) + (r.search_rounds == 1 ? " search" : " searches") +
         (r.replay_rounds == 0 ? ""
          : " and " + std::to_string(r.replay_rounds) + " replay" + (r.replay_rounds == 1 ? "" : "s") + " of the proof");
}

namespace {

std::string unreachable_text(const PlanningResult& r, const Reachability& reach) {
  return "no sequence of these primitives makes the design: none of the " + std::to_string(reach.states) +
         " states they reach (costs aside, each primitive any number of times) is within tolerance. The nearest " +
         nearest_text(r, reach) +
         ". Deposits cannot reach under material already there, and removals cannot spare design they pass through";
}

// Takes what execution showed out of the problem's primitives.
void take_in(Learning& learning, PlanningResult& r) {
  for (const Shortfall& s : learning.pending) {
    PrimitiveSpec& prim = r.problem.primitives[std::size_t(s.primitive)];
    if (s.spill) {
      prim.atoms.set(s.atom);  // it deposits there too, wherever the plan stands
    } else {
      if (prim.falls_short.words().empty()) prim.falls_short = AtomSet(int(r.problem.atoms.size()));
      prim.falls_short.set(s.atom);
    }
    r.learned.push_back(s);
  }
  learning.pending.clear();
}

// What execution showed may leave the corrected problem with no plan: the proof (a quarter
// of the first one's budget) says so in a moment, where a search would run to its limit.
// A plan it replays is executed before another search (which would likely offer it first);
// failing, it corrects the problem again without a search; passing, it leads the next
// search's seeds, ahead of the stocks' (one no longer reaching the design is passed over).
CoreProof correct_by_replays(SearchOptions& search, std::int64_t max_rejected, Learning& learning, PlanningResult& r) {
  for (;;) {
    CoreProof corrected = prove_by_core(r.problem, quick_proof_limits());
    if (corrected.outcome != CoreProof::Outcome::Feasible) return corrected;
    search.seeds = start_seeds(r.stock_starts);
    search.seeds.insert(search.seeds.begin(), corrected.sequence);
    Plan replay;
    if (!search.accept || !simulate(r.problem, corrected.sequence, replay) || !is_goal(r.problem, replay.final_state) ||
        std::int64_t(r.rejected.size()) >= max_rejected || r.search_rounds + r.replay_rounds >= kMaxLearningRounds)
      return corrected;
    const std::size_t rejected = r.rejected.size();
    if (search.accept(replay) || learning.pending.empty()) {
      if (r.rejected.size() > rejected) search.seeds.erase(search.seeds.begin());  // failed, showed nothing
      return corrected;
    }
    ++r.replay_rounds;
    take_in(learning, r);
  }
}

void search_plans(int top_k, const PlanningOptions& options, const Progress& progress, PlanningResult& r,
                  double& validation_seconds) {
  progress("search", 0);
  SearchOptions search{top_k, options.max_expansions};
  // Plans that differ only in the order of one tool's consecutive actions in one setup
  // are one plan to a shop: the search keeps the cheapest order of each such block.
  search.block_orders = BlockOrders::Cheapest;
  search.distinct_effects = true;
  search.time_limit = options.search_time;
  Learning learning;
  search.accept = accept_hook(options, r, validation_seconds, learning);
  search.known_to_fail = known_failure_hook(options, r);
  search.max_rejected = options.max_rejected;
  if (r.core_proof.outcome == CoreProof::Outcome::Feasible) search.seeds.push_back(r.core_proof.sequence);
  for (std::vector<int>& seed : start_seeds(r.stock_starts)) search.seeds.push_back(std::move(seed));
  // A rejection that showed a primitive falling short stops the search: the next one runs
  // on the problem without what the primitive does not do (planner/pipeline/shortfall.hpp).
  if (options.learn)
    search.interrupt = [&learning, &r]() {
      return !learning.pending.empty() && r.search_rounds + r.replay_rounds < kMaxLearningRounds;
    };
  r.validated = bool(options.validate);
  const auto started = std::chrono::steady_clock::now();
  SearchStats total;
  bool proven_after_learning = false;
  for (;;) {
    ++r.search_rounds;
    SearchStats round;
    r.plans = find_plans(r.problem, search, &round);
    total += round;
    if (!round.interrupted) break;
    take_in(learning, r);
    CoreProof corrected = correct_by_replays(search, options.max_rejected, learning, r);
    if (corrected.outcome == CoreProof::Outcome::Proven) {
      r.plans.clear();
      r.core_proof = std::move(corrected);
      proven_after_learning = true;
      break;
    }
    // The rounds share the budgets: turned-down plans and seconds.
    search.max_rejected = std::max<std::int64_t>(1, options.max_rejected - std::int64_t(r.rejected.size()));
    if (options.search_time > 0)
      search.time_limit = std::max(
          0.05, options.search_time - std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count());
  }
  r.search = total;
  if (proven_after_learning) {
    r.search.limit_reached = false;
    r.search.exhausted = true;
    // A correction is not a proof (docs/validation.md): the verdict stays undecided, and
    // says that the search is over and why.
    r.verdict = core_verdict(r.problem, r.core_proof, r.measures, r.lattice);
    r.verdict.decided_without_search = false;
    r.verdict.summary = "no plan is left once the primitives are corrected by what execution showed (" +
                        std::to_string(r.rejected.size()) + " candidate" + (r.rejected.size() == 1 ? "" : "s") +
                        " rejected; " + learned_text(r) + "): on the corrected primitives, " + r.verdict.summary +
                        ". The correction may also rule out plans that would work";
    progress("search", 1);
    return;
  }
  std::string undecided_hint;
  if (r.plans.empty() && r.search.limit_reached && !r.verdict.decided_without_search) {
    // The search stopped without a plan: maybe none exists. Exploring what the primitives
    // reach at all, costs aside, can prove it.
    const Reachability reach = explore_reachable(r.problem);
    if (reach.complete && !reach.goal && r.learned.empty()) {
      r.search.limit_reached = false;
      r.search.exhausted = true;
      r.verdict.outcome = Verdict::Outcome::NotManufacturable;
      r.verdict.summary = unreachable_text(r, reach);
      progress("search", 1);
      return;
    }
    if (!reach.goal)
      undecided_hint = "; of the " + std::to_string(reach.states) +
                       " states explored (costs aside, the exploration's limit), none is within tolerance, and the "
                       "nearest " + nearest_text(r, reach);
  }
  progress("search", 1);
  const CoreProof& proof = r.core_proof;
  if (r.plans.empty() && !r.verdict.decided_without_search && proof.reuse_needed > r.problem.max_uses) {
    std::string sequence;
    for (const int i : proof.sequence) sequence += (sequence.empty() ? "" : ", ") + r.problem.primitives[std::size_t(i)].name;
    undecided_hint += "; the proof before the search found a sequence that makes the design using a primitive " +
                      std::to_string(proof.reuse_needed) + " times (" + sequence + "): --reuse " +
                      std::to_string(proof.reuse_needed) + " lets the search take it";
  }
  if (r.plans.empty() && !r.verdict.decided_without_search && !r.learned.empty())
    undecided_hint += "; " + learned_text(r) + ", which may also rule out plans that would work";
  if (r.plans.empty() && !r.verdict.decided_without_search) {
    r.verdict.outcome = Verdict::Outcome::NotManufacturable;
    r.verdict.summary = !r.rejected.empty()
                            ? "every candidate plan failed when executed (" + std::to_string(r.rejected.size()) +
                                  " rejected" + (r.search.limit_reached ? ", the search stopped at its limit" : "") + ")" +
                                  (r.learned.empty() ? std::string()
                                                     : "; " + learned_text(r) +
                                                           ", which may also rule out plans that would work")
                        : r.search.limit_reached
                            ? "undecided: no plan found within the search limits (" + std::to_string(r.search.expanded) +
                                  " states expanded, weighted A* included); no atom rules the part out, but the "
                                  "primitives may not combine into it" + undecided_hint
                            : "no sequence of these primitives makes the design";
    if (r.faces.passed_over > 0)
      r.verdict.summary += "; " + std::to_string(r.faces.passed_over) + " plan" + (r.faces.passed_over == 1 ? "" : "s") +
                           " the search found leave a face as deposited where its deposit may not (the first: " +
                           r.faces.first_passed + ")";
  }
}

}  // namespace

// When the proof before the search stopped at its budget, a longer one runs on another
// core while the search does: it decides parts the search cannot, and is stopped as soon
// as the search has a plan. It works on its own copy of the problem, the one before any
// learning: the search corrects its problem as candidates fail.
void search_phase(int top_k, const PlanningOptions& options, const Progress& progress,
                                  PlanningResult& r, double& validation_seconds) {
  if (r.core_proof.outcome != CoreProof::Outcome::Unknown || r.verdict.modality != Modality::Hybrid) {
    search_plans(top_k, options, progress, r, validation_seconds);
    return;
  }
  std::atomic<bool> stop{false};
  CoreProofLimits limits;
  limits.max_states = kLongerProofStates;
  limits.stop = &stop;
  const PlanningProblem problem = r.problem;
  CoreProof longer;
  std::thread prover([&] {
    try {
      longer = prove_by_core(problem, limits);
    } catch (const std::bad_alloc&) {
      longer = {};  // out of memory: no verdict from it, the search's stands
    }
  });
  try {
    search_plans(top_k, options, progress, r, validation_seconds);
  } catch (...) {
    stop = true;
    prover.join();
    throw;
  }
  if (!r.plans.empty()) stop = true;
  prover.join();
  if (!r.plans.empty() || longer.outcome != CoreProof::Outcome::Proven) return;
  r.core_proof = std::move(longer);
  r.verdict = core_verdict(problem, r.core_proof, r.measures, r.lattice);
  r.search.limit_reached = false;
  r.search.exhausted = true;
}

void settle_outcome(PlanningResult& r) {
  if (r.verdict.manufacturable() && !r.plans.empty()) return;
  const bool undecided = (r.search.limit_reached || !r.learned.empty()) && !r.verdict.decided_without_search;
  r.verdict.outcome = undecided ? Verdict::Outcome::Undecided : Verdict::Outcome::NotManufacturable;
}

}  // namespace hybridctl::planner
