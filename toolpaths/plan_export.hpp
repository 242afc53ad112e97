#pragma once
// A plan's actions as G-code: replay the plan on the voxels, take each action's region of
// influence in the state it meets (deposit: P minus the material there; removal: the
// material there inside P), make its toolpath in its setup's frame, and post-process.
// The state an action meets is the plan's planned state, or, when the layer above runs
// the programs (ExportOptions::material_after, validation/), the material really present
// after the previous actions' toolpaths: travel, clearance heights and blocked columns are
// then planned against what the machine will meet.
//
// The raw stock action makes no G-code: the operator clamps the stock (its name goes in
// the program header). Actions whose region is empty in their state are skipped with a
// note; so are none else: an action the machine cannot make (a primitive from a file, a
// head or tool the machine lacks) is an error.

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "config/machine.hpp"
#include "toolpaths/arc_fit.hpp"
#include "toolpaths/deposition_path.hpp"
#include "toolpaths/pocket_path.hpp"
#include "gcode/post.hpp"
#include "toolpaths/toolpath.hpp"
#include "plan/plan_file.hpp"

namespace hybridctl::toolpaths {

struct ExportOptions {
  DepositionOptions deposition;
  PocketOptions pocket;
  // Circular runs of feed moves (wall finishing's round joins and offsets, deposition
  // contours) as G2/G3 arcs within arcs.chord_tolerance (0.001 mm: within the finishing's
  // own accuracy); `arcs.output = ArcOutput::Lines` keeps the generators' G1 chords.
  ArcFitOptions arcs;
  gcode::PostOptions post;
  // Progress: the action being made (1-based) of how many.
  std::function<void(int action, int actions)> progress;
};

// One action of the plan with its geometry.
struct ExportedAction {
  int step = 0;                // 1-based in the plan
  std::string primitive;       // P-name
  bool makes_gcode = false;    // false for the raw stock, empty regions and paths with no move
  std::string note;            // why not, or the stock to clamp
  geometry::Solid before;      // material the action meets (part frame): planned, or present (material_after)
  geometry::Solid after;       // `before` with the action's primitive applied (AM unites, SM subtracts)
  geometry::Solid roi;         // its region of influence in `before`
  // After it, what deposits laid that no removal has finished since (part frame): a later
  // removal finishes the walls of it next to its region (PocketOptions::laid).
  geometry::Solid laid;
  ActionProgram program;       // when makes_gcode; a path with no move keeps its defects here
};

// The material present after an action, as the layer above finds it by running the
// action's program (part frame, on the plan's lattice and domain).
using MaterialAfter = std::function<geometry::Solid(const ExportedAction& made)>;

struct PlanExport {
  std::string raw_stock;                 // label of the stock the plan starts from, if any
  std::vector<ExportedAction> actions;   // every action of the plan, in order
  std::vector<ActionProgram> programs() const;  // those that make G-code
};

// Throws hybridctl::InputError when the plan was made for another machine, or an action
// needs an instrument or setup the machine does not have.
// `material_after`, when given, is asked after every action (the raw stock and actions
// with nothing to do included) and the next action meets what it returns instead of the
// planned state.
PlanExport export_plan(const plan::PlanFile& file, const plan::PlanFilePlan& plan, const config::Machine& machine,
                       const ExportOptions& options = {}, const MaterialAfter& material_after = {});

// Where export starts when the first actions of the plan were made before, with the same
// file, machine and options (validation/ resumes candidates from a prefix it executed):
// those actions as they were made (their solids may be left out), and the material
// present after them, as `material_after` returned it. Export goes on from the next action
// as it would have had it made them itself.
struct ExportStart {
  std::vector<ExportedAction> actions;
  geometry::Solid present;
};

// export_plan from `start`; `material_after` is required (std::invalid_argument otherwise).
// The actions of `start` come first in the result; progress is called for the others.
PlanExport export_plan(const plan::PlanFile& file, const plan::PlanFilePlan& plan, const config::Machine& machine,
                       const ExportOptions& options, const MaterialAfter& material_after, ExportStart start);

// Action `k` (0-based) of `plan` as export_plan without material_after makes it: against
// the planned states `planned` (plan::plan_states(file, plan)). It depends only on the
// actions up to it, so plans that begin alike share it (the report exports each once).
// std::invalid_argument for a `k` the plan does not have or states that are not its.
ExportedAction export_planned_action(const plan::PlanFile& file, const plan::PlanFilePlan& plan, int k,
                                     const std::vector<geometry::Solid>& planned, const config::Machine& machine,
                                     const ExportOptions& options = {});

// The path defects of the actions, each as "action K (P..): message".
// Export refuses a plan that has any (docs/export.md): the part would be wrong.
std::vector<std::string> path_defects(const PlanExport& exported);

}  // namespace hybridctl::toolpaths
