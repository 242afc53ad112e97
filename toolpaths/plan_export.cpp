#include "toolpaths/plan_export.hpp"

#include <algorithm>
#include <optional>
#include <stdexcept>

#include "common/error.hpp"
#include "instruments/bead.hpp"
#include "plan/start_stock.hpp"
#include "toolpaths/setup_frame.hpp"

namespace hybridctl::toolpaths {
namespace {

const config::Setup& setup_named(const config::Machine& m, const plan::PlanFilePrimitive& p) {
  for (const auto& s : m.setups)
    if (s.name == p.setup) return s;
  throw InputError(p.name + " (" + p.label + "): the machine '" + m.name + "' has no setup '" + p.setup +
                   "'; expected one of its setups");
}

// Where the simulated machine has its build plate in `setup`'s work frame: under the
// lowest voxel layer of the box it works in (plan::simulated_domain; for a plan that
// starts by depositing, that box starts at the first deposit's lowest layer in its setup).
// A deposit onto nothing has the plate under its own first layer (the toolpath's default).
double plate_z(const plan::PlanFile& file, const geometry::IndexBox& simulated, const config::Setup& setup) {
  return file.lattice.origin.z + part_to_work(simulated, file.lattice, setup.approach).lo.z * file.lattice.voxel_size;
}

// The action's toolpath from its region of influence in the material it meets.
// `counted_on`: DepositionOptions::counted_on, or null.
void make_program(const plan::PlanFile& file, const geometry::IndexBox& simulated, const plan::PlanFilePrimitive& p,
                  const config::Machine& machine, const ExportOptions& options, ExportedAction& a,
                  const geometry::Solid* counted_on) {
  const config::Setup& setup = setup_named(machine, p);
  ActionProgram& prog = a.program;
  prog.action = a.step;
  prog.primitive = p.name;
  prog.label = p.label;
  prog.additive = p.mode == config::Mode::Additive;
  prog.volume = a.roi.volume();
  if (prog.additive) {
    const config::AdditiveHead* head = nullptr;
    std::size_t index = 0;
    for (const auto& h : machine.heads) {
      if (h.name == p.capability) {
        head = &h;
        break;
      }
      ++index;
    }
    if (!head) throw InputError(p.name + " (" + p.label + "): the machine has no head '" + p.capability + "'");
    DepositionOptions d = options.deposition;
    d.fallback_tool_number = instruments::head_tool_number(machine, index);
    if (!d.build_plate_z && !a.before.empty()) d.build_plate_z = plate_z(file, simulated, setup);
    d.counted_on = counted_on;
    prog.path = deposition_path(a.roi, a.before, *head, setup, d);
  } else {
    const config::CuttingTool* tool = machine.find_tool(p.tool_number);
    if (!tool) throw InputError(p.name + " (" + p.label + "): the machine has no tool T" + std::to_string(p.tool_number));
    prog.path = pocket_path(a.roi, a.after, a.before, *tool, setup, options.pocket);
  }
  // A path with no move makes no G-code: its block would only approach the path's
  // (meaningless) start. Why stays in the note, its defects in the program.
  a.makes_gcode = !prog.path.moves.empty();
  if (!a.makes_gcode) {
    const auto& why = prog.path.defects.empty() ? prog.path.warnings : std::vector<std::string>{prog.path.defects[0].message};
    a.note = "no toolpath" + (why.empty() ? std::string() : ": " + why.front());
  }
}

}  // namespace

std::vector<ActionProgram> PlanExport::programs() const {
  std::vector<ActionProgram> out;
  for (const auto& a : actions)
    if (a.makes_gcode) out.push_back(a.program);
  return out;
}

std::vector<std::string> path_defects(const PlanExport& exported) {
  std::vector<std::string> out;
  for (const ExportedAction& a : exported.actions)
    for (const gcode::PathDefect& d : a.program.path.defects)  // made or not
      out.push_back("action " + std::to_string(a.step) + " (" + a.primitive + "): " + d.message);
  return out;
}

namespace {

void check_machine(const plan::PlanFile& file, const config::Machine& machine) {
  if (file.machine_name != machine.name)
    throw InputError("the plan was made for machine '" + file.machine_name + "', not '" + machine.name +
                     "'; expected the machine file it was planned with (" + file.machine_file + ")");
}

// Action `k` of the plan, meeting `before`; `after` is the planned state after it, or
// null when the material present is fed back (the action's primitive applied to `before`).
// `planned_before`, with the material fed back: the plan's state before the action, which
// tells the part of a deposit's ROI the plan counts on it for (DepositionOptions::counted_on).
ExportedAction make_action(int k, geometry::Solid before, const geometry::Solid* after, const geometry::IndexBox& simulated,
                           const plan::PlanFile& file, const plan::PlanFilePlan& plan,
                           const config::Machine& machine, const ExportOptions& options,
                           const geometry::Solid* planned_before = nullptr) {
  const plan::PlanFilePrimitive& p = file.primitives.at(std::size_t(plan.actions.at(std::size_t(k)).primitive));
  const bool additive = p.mode == config::Mode::Additive;
  ExportedAction a;
  a.step = k + 1;
  a.primitive = p.name;
  a.before = std::move(before);
  a.after = after ? *after : additive ? unite(a.before, p.region) : subtract(a.before, p.region);
  a.roi = additive ? subtract(p.region, a.before) : intersect(a.before, p.region);
  if (p.raw_stock()) {
    a.note = "clamp the raw stock: " + p.label;
  } else if (a.roi.empty()) {
    a.note = "nothing to " + std::string(additive ? "deposit" : "remove") + " in this state";
  } else if (p.kind == config::PrimitiveKind::File) {
    throw InputError(p.name + " is a primitive from the file " + p.capability +
                     ": no head or tool of the machine is known to make it; expected machine primitives only");
  } else {
    // With the material fed back, the part of a deposit's ROI the plan counts on it for:
    // what its primitive adds to the planned state before it.
    const std::optional<geometry::Solid> counted_on =
        additive && planned_before ? std::optional(subtract(a.roi, *planned_before)) : std::nullopt;
    make_program(file, simulated, p, machine, options, a, counted_on ? &*counted_on : nullptr);
  }
  return a;
}

// Actions `first`.. of the plan into `out`; `present` is the material the first one meets
// when the material present is fed back, `planned` the planned states otherwise.
void export_from(int first, geometry::Solid present, const std::vector<geometry::Solid>& planned,
                 const plan::PlanFile& file, const plan::PlanFilePlan& plan, const config::Machine& machine,
                 const ExportOptions& options, const MaterialAfter& material_after, PlanExport& out) {
  const int n = int(plan.actions.size());
  const geometry::IndexBox simulated = plan::simulated_domain(file, plan, machine);
  for (int k = first; k < n; ++k) {
    if (options.progress) options.progress(k + 1, n);
    const plan::PlanFilePrimitive& p = file.primitives[std::size_t(plan.actions[std::size_t(k)].primitive)];
    if (p.raw_stock()) out.raw_stock = p.label;
    const geometry::Solid* planned_before = planned.empty() ? nullptr : &planned[std::size_t(k)];
    ExportedAction a = material_after
                           ? make_action(k, present, nullptr, simulated, file, plan, machine, options, planned_before)
                           : make_action(k, planned[std::size_t(k)], &planned[std::size_t(k) + 1], simulated, file, plan,
                                         machine, options);
    if (material_after) present = material_after(a);
    out.actions.push_back(std::move(a));
  }
}

}  // namespace

PlanExport export_plan(const plan::PlanFile& file, const plan::PlanFilePlan& plan, const config::Machine& machine,
                       const ExportOptions& options, const MaterialAfter& material_after) {
  check_machine(file, machine);
  PlanExport out;
  const std::vector<geometry::Solid> planned = plan::plan_states(file, plan);
  export_from(0, planned.front(), planned, file, plan, machine, options, material_after, out);
  return out;
}

PlanExport export_plan(const plan::PlanFile& file, const plan::PlanFilePlan& plan, const config::Machine& machine,
                       const ExportOptions& options, const MaterialAfter& material_after, ExportStart start) {
  if (!material_after) throw std::invalid_argument("export_plan: a start needs material_after");
  if (start.actions.size() > plan.actions.size())
    throw std::invalid_argument("export_plan: a start with more actions than the plan");
  check_machine(file, machine);
  PlanExport out;
  // The raw stock's label, as the actions of the start set it.
  for (std::size_t k = 0; k < start.actions.size(); ++k) {
    const plan::PlanFilePrimitive& p = file.primitives.at(std::size_t(plan.actions[k].primitive));
    if (p.raw_stock()) out.raw_stock = p.label;
  }
  const int first = int(start.actions.size());
  out.actions = std::move(start.actions);
  // The planned states tell what the plan counts on a deposit for: none needed when only
  // removals remain.
  const bool deposits = std::any_of(plan.actions.begin() + first, plan.actions.end(), [&](const plan::PlanFileAction& a) {
    return file.primitives.at(std::size_t(a.primitive)).mode == config::Mode::Additive;
  });
  export_from(first, std::move(start.present), deposits ? plan::plan_states(file, plan) : std::vector<geometry::Solid>{},
              file, plan, machine, options, material_after, out);
  return out;
}

ExportedAction export_planned_action(const plan::PlanFile& file, const plan::PlanFilePlan& plan, int k,
                                     const std::vector<geometry::Solid>& planned, const config::Machine& machine,
                                     const ExportOptions& options) {
  if (k < 0 || std::size_t(k) >= plan.actions.size() || planned.size() != plan.actions.size() + 1)
    throw std::invalid_argument("export_planned_action: no action " + std::to_string(k) + " or not the plan's states");
  check_machine(file, machine);
  return make_action(k, planned[std::size_t(k)], &planned[std::size_t(k) + 1], plan::simulated_domain(file, plan, machine),
                     file, plan, machine, options);
}

}  // namespace hybridctl::toolpaths
