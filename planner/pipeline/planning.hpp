#pragma once
// One planning job from end to end: voxelize the design, compute the machine's
// primitives (and any given as files), decompose into atoms, check, search.

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "config/machine.hpp"
#include "geometry/mesh.hpp"
#include "planner/atoms/atoms.hpp"
#include "planner/search/core_proof.hpp"
#include "planner/search/start_proofs.hpp"
#include "planner/atoms/fine_graining.hpp"
#include "planner/atoms/check.hpp"
#include "planner/costing/costs.hpp"
#include "plan/candidate_run.hpp"
#include "plan/deviation.hpp"
#include "planner/primitives/machine_primitives.hpp"
#include "plan/rejection.hpp"
#include "planner/search/search.hpp"
#include "planner/pipeline/shortfall.hpp"

namespace hybridctl::planner {

// A primitive given as a file (STL or .vdb) with its mode.
struct PrimitiveFile {
  std::string path;
  Mode mode = Mode::Additive;
  double cost_per_mm3 = 1.0;
};

struct PlanningResult;

// How often the search starts again on a problem corrected by shortfalls: each round
// costs a search, and a model still wrong after this many corrections is left to the
// rejections alone.
inline constexpr int kMaxLearningRounds = 8;

struct PlanningOptions {
  // Unset values (<= 0, or top_k 0) take the machine file's planning defaults.
  double voxel_size = 0;
  double tolerance = -1;
  double sliver_threshold = -1;
  int top_k = 0;
  int max_uses = 1;
  // Expanded states per search (the exact one, then each weighted one): about a second
  // each per 1,000 on the B-axis machine's 1,758 atoms. Deterministic, unlike a time budget.
  std::int64_t max_expansions = 10'000;
  // Wall-clock budget of the plan search in seconds (SearchOptions::time_limit; 0: none).
  double search_time = 0;
  std::vector<PrimitiveFile> extra_primitives;
  // Banded primitives (planner/primitives/bands.hpp): "mill up to here, deposit from here on".
  bool bands = true;
  // Iterative fine-graining (planner/atoms/fine_graining.hpp): split atoms that straddle the
  // design with primitives restricted to their neighbourhood.
  bool fine_graining = true;
  // Filled deposits (planner/primitives/filled.hpp): overfill with holes and overhangs filled
  // solid, where milling can open them again.
  bool filled = true;
  // Shortfalls that validation reports correct the problem and restart the search
  // (planner/pipeline/shortfall.hpp); false: rejections only pass plans over.
  bool learn = true;
  // What the search minimises (planner/costing/costs.hpp); unset: the machine file's.
  std::optional<config::Objective> objective;
  // Raw stocks as files (STL or .vdb on the plan's grid) in the part's frame: a casting, a
  // blank, a worn part to repair. When given, they replace the machine file's raw stocks.
  std::vector<std::string> stock_files;
  // Bytes planning may take (planner/pipeline/memory_estimate.hpp); 0: half the physical memory.
  std::uint64_t memory_budget = 0;
  // Progress: a phase name and a fraction of it done.
  std::function<void(const std::string& phase, double fraction)> progress;
  // Validation by execution (validation/): when set, every plan the search finds is
  // offered to it, cheapest first, with the result as far as planning has made it (grid,
  // design, primitives, atoms, problem). No reasons: the plan is kept; reasons: it is
  // recorded in PlanningResult::rejected and the search goes on to the next candidate,
  // until top_k plans are kept, the plans run out, or `max_rejected` were turned down.
  // Shortfalls with the reasons (planner/pipeline/shortfall.hpp) correct the problem: each takes its
  // atom out of its primitive, and the search starts again on the corrected problem, at
  // most kMaxLearningRounds times.
  std::function<CandidateCheck(const PlanningResult&, const Plan&)> validate;
  // Asked before `validate`: a candidate it would turn down without executing it (it
  // repeats a failure executed before), which the search passes over uncounted.
  std::function<bool(const PlanningResult&, const Plan&)> known_failure;
  // After the search: an offered plan's actions' cycle times in minutes from their
  // toolpaths (validation records them as it proves plans; empty: unknown). Where they
  // are far from the estimate the plans are ranked by them (planner/costing/toolpath_rank.hpp).
  std::function<std::vector<double>(const Plan&)> toolpath_minutes;
  // After the search: an offered plan's whole program's cycle time (validation records it
  // as it proves plans; none: unknown).
  std::function<std::optional<plan::CycleTime>(const Plan&)> cycle_time;
  // After the search: an offered plan's part measured against the design's real surface
  // (validation records it as it proves plans; none: not verified exactly).
  std::function<std::optional<plan::ExactDeviation>(const Plan&)> exact_deviation;
  std::int64_t max_rejected = 200;
  // Before the search: the design's inside corners no cutter of the machine reaches
  // (validation sets it: plan::CandidateValidator::corners). Where no head lays walls
  // within the tolerance either, the part is refused over them
  // (planner/pipeline/unreached_corners.hpp); unset: not asked.
  plan::CornerFinder corners;
};

// A candidate plan that validation turned down, with its reasons.
struct RejectedPlan {
  Plan plan;
  std::vector<plan::RejectionReason> reasons;
};

struct PlanningResult {
  geometry::Lattice lattice;
  geometry::IndexBox domain;
  geometry::Solid design;
  double design_volume = 0;        // mm^3
  double bounding_box_volume = 0;  // mm^3: the cost normaliser
  double tolerance = 0;  // mm, the part's: exact verification holds the plans to it
  double band = 0;       // mm, the planning band the voxels are judged with (plan/planning_band.hpp)
  geometry::TriangleMesh design_mesh;  // the part as given (plan::PlanFile::design_mesh)
  double sliver_threshold = 0;
  std::vector<Primitive> primitives;
  AtomDecomposition atoms{geometry::Lattice{}, geometry::IndexBox{{0, 0, 0}, {1, 1, 1}}};
  std::vector<AtomMeasures> measures;
  PlanningProblem problem;
  Verdict verdict;
  // The inside corners a refusal rests on, when it rests on them (unreached_corners.hpp).
  std::vector<plan::UnreachedCorner> unreached_corners;
  // A refusal's located regions in a shop's words (planner/pipeline/shop_words.hpp): its
  // air, and design no head builds over an overhang; empty for a part with plans.
  std::vector<std::string> in_shop_words;
  std::vector<Plan> plans;
  std::vector<plan::Deviation> deviations;  // one per plan: its outcome against the design, on the voxels
  // One per plan: the part its program makes against the design's real surface (none:
  // planned without validation, or a design without a real surface).
  std::vector<std::optional<plan::ExactDeviation>> exact_deviations;
  std::vector<RejectedPlan> rejected;  // candidates validation turned down, in the order found
  // What execution showed the primitives do not do (taken out of `problem`'s primitives),
  // in the order learned, how many searches ran (1 + the restarts they caused), and how
  // many corrections came from executing the proof's replay between searches.
  std::vector<Shortfall> learned;
  int search_rounds = 0;
  int replay_rounds = 0;
  // Faces each deposit may not leave as it lays them (planner/pipeline/deposited_faces.hpp),
  // and the plans the search passed over for it.
  FaceRule faces;
  bool validated = false;              // the plans were validated (PlanningOptions::validate)
  SearchStats search;
  FineGraining fine_graining;  // what fine-graining added, and what it could not split
  // The proof from a few atoms tried before the search (planner/search/core_proof.hpp); Proven
  // decides the verdict.
  CoreProof core_proof;
  // Each raw stock proven on its own before the search: whether a plan starts from it
  // (planner/search/start_proofs.hpp); those that start none are `never_first` in `problem`.
  std::vector<StartProof> stock_starts;
  // What the plans' costs are in (minutes, money or cost factors), and each plan's
  // estimate in minutes and money whatever the objective, with the machine's currency.
  config::Objective objective = config::Objective::CostFactor;
  std::vector<PlanEstimate> estimates;  // one per plan
  std::string currency;
  // Per plan, per action: the minutes of motion and dwell of its program (empty: not
  // known), and whether the plans were ranked by them because some estimate was far off.
  std::vector<std::vector<double>> toolpath_minutes;
  // Per plan: its whole program's cycle time, changes included (none: not known).
  std::vector<std::optional<plan::CycleTime>> cycle_times;
  bool ranked_by_toolpaths = false;
  int estimates_off = 0;  // actions whose estimate is more than kEstimateTolerance off their toolpath's time
  std::vector<std::size_t> search_rank;  // per plan: its rank (0 = first) in the search's order
  std::vector<double> toolpath_costs;    // ranked_by_toolpaths: per plan, its cost with the toolpaths' times
  std::vector<std::pair<std::string, double>> timings;  // phase, seconds
};

// Throws hybridctl::InputError for bad inputs (open mesh, unreadable primitive file,
// a .vdb primitive on another lattice).
PlanningResult plan_part(const geometry::TriangleMesh& part, const std::string& part_name,
                         const config::Machine& machine, const PlanningOptions& options);

// What execution showed the primitives do not do (PlanningResult::learned), in a phrase:
// how many primitives and atoms, the largest, and the searches; empty when nothing was learned.
std::string learned_text(const PlanningResult& result);

// The solid a plan leaves: the union of the atoms in its final state.
geometry::Solid plan_outcome(const PlanningResult& result, const Plan& plan);
// The atoms an action of a plan deposits or removes (its region of influence).
AtomSet step_region(const PlanningResult& result, const Plan& plan, std::size_t step);

}  // namespace hybridctl::planner
