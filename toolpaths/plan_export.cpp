#include "toolpaths/plan_export.hpp"

#include <algorithm>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>

#include "common/error.hpp"
#include "instruments/bead.hpp"
#include "plan/start_stock.hpp"
#include "toolpaths/setup_frame.hpp"

namespace hybridctl::toolpaths {
namespace {

// The design's flat faces a tool in this setup cuts down to: those whose outward normal
// points at the tool, in the setup's work frame (their three vertices at one height).
std::vector<geometry::Triangle> floors_facing(const std::vector<geometry::Triangle>& faces, config::Approach approach) {
  const geometry::Vec3 towards = approach_vector(approach);
  std::vector<geometry::Triangle> out;
  for (const geometry::Triangle& t : faces) {
    const geometry::Vec3 u{t[1].x - t[0].x, t[1].y - t[0].y, t[1].z - t[0].z};
    const geometry::Vec3 v{t[2].x - t[0].x, t[2].y - t[0].y, t[2].z - t[0].z};
    const geometry::Vec3 n{u.y * v.z - u.z * v.y, u.z * v.x - u.x * v.z, u.x * v.y - u.y * v.x};
    if (n.x * towards.x + n.y * towards.y + n.z * towards.z <= 0) continue;
    geometry::Triangle w{part_to_work(t[0], approach), part_to_work(t[1], approach), part_to_work(t[2], approach)};
    if (w[0].z != w[1].z || w[1].z != w[2].z) continue;  // square to another axis
    out.push_back(w);
  }
  return out;
}

// The design's STL in each setup's work frame, cleaned (geometry::clean_mesh: wall finishing
// counts facets even-odd, as the voxelizer does) and turned once per approach: shared by
// every milling action of an export rather than copied per action.
class DesignFrames {
 public:
  explicit DesignFrames(const geometry::TriangleMesh& mesh) : mesh_(mesh) {}
  std::shared_ptr<const std::vector<geometry::Triangle>> in(config::Approach approach) {
    if (mesh_.triangles.empty()) return nullptr;
    auto& slot = frames_[approach];
    if (!slot) {
      if (!cleaned_) cleaned_ = geometry::clean_mesh(mesh_);
      auto turned = std::make_shared<std::vector<geometry::Triangle>>();
      turned->reserve(cleaned_->triangles.size());
      for (const geometry::Triangle& t : cleaned_->triangles)
        turned->push_back({part_to_work(t[0], approach), part_to_work(t[1], approach), part_to_work(t[2], approach)});
      slot = std::move(turned);
    }
    return slot;
  }

 private:
  const geometry::TriangleMesh& mesh_;
  std::optional<geometry::TriangleMesh> cleaned_;
  std::map<config::Approach, std::shared_ptr<const std::vector<geometry::Triangle>>> frames_;
};

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
// `counted_on`: DepositionOptions::counted_on, or null. `design`: the design's STL a
// removal finishes its walls on, or null for one that cuts into the design on purpose.
void make_program(const plan::PlanFile& file, const geometry::IndexBox& simulated, const plan::PlanFilePrimitive& p,
                  const config::Machine& machine, const ExportOptions& options, ExportedAction& a,
                  const geometry::Solid* counted_on, DesignFrames* design, const geometry::Solid* laid) {
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
    // A near-net deposit's beads end on the design's real walls.
    if (design && p.kind == config::PrimitiveKind::UAm) {
      d.near_net_design = design->in(setup.approach);
      d.near_net_slack = std::max(0.0, file.tolerance - head->accuracy) / 2;
    }
    prog.path = deposition_path(a.roi, a.before, *head, setup, d);
  } else {
    const config::CuttingTool* tool = machine.find_tool(p.tool_number);
    if (!tool) throw InputError(p.name + " (" + p.label + "): the machine has no tool T" + std::to_string(p.tool_number));
    PocketOptions pocket = options.pocket;
    pocket.floors = floors_facing(geometry::axis_square_faces(file.design_mesh), setup.approach);
    if (design) {
      pocket.design = design->in(setup.approach);
      pocket.design_voxels = &file.design;
      // A third of the tolerance for the scallops: room for a slope's wider ones and for
      // what the finishing's thinning and the controller's rounding add.
      if (file.tolerance > 0) pocket.scallop = file.tolerance / 3;
      pocket.finish_region = &p.region;
      pocket.laid = laid;
    }
    prog.path = pocket_path(a.roi, a.after, a.before, *tool, setup, pocket);
  }
  // Milling paths and deposition contours whose feed moves follow circles, as arcs
  // (rasters and lattice steps are straight and stay as they are).
  if (options.arcs.output == ArcOutput::Fit) prog.path = fit_arcs(std::move(prog.path), options.arcs);
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
                           const config::Machine& machine, const ExportOptions& options, DesignFrames& design,
                           const geometry::Solid& laid, const geometry::Solid* planned_before = nullptr) {
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
  } else if (a.roi.empty() && (additive || laid.empty())) {
    a.note = "nothing to " + std::string(additive ? "deposit" : "remove") + " in this state";
  } else if (p.kind == config::PrimitiveKind::File) {
    throw InputError(p.name + " is a primitive from the file " + p.capability +
                     ": no head or tool of the machine is known to make it; expected machine primitives only");
  } else {
    // With the material fed back, the part of a deposit's ROI the plan counts on it for:
    // what its primitive adds to the planned state before it.
    const std::optional<geometry::Solid> counted_on =
        additive && planned_before ? std::optional(subtract(a.roi, *planned_before)) : std::nullopt;
    // A removal that takes design material a later deposit lays again cuts past the
    // design's walls on purpose (SM-cons: mill past the design, then deposit): its walls
    // are not finished. Design voxels it takes that nothing lays again (the plan may drop
    // them within its band) are the design's to keep: wall finishing keeps them.
    bool cuts_design = false;
    if (!additive) {
      const geometry::Solid cut = intersect(a.roi, file.design);
      for (std::size_t j = std::size_t(k) + 1; j < plan.actions.size() && !cut.empty() && !cuts_design; ++j) {
        const plan::PlanFilePrimitive& later = file.primitives.at(std::size_t(plan.actions[j].primitive));
        cuts_design = later.mode == config::Mode::Additive && !intersect(cut, later.region).empty();
      }
    }
    make_program(file, simulated, p, machine, options, a, counted_on ? &*counted_on : nullptr,
                 cuts_design ? nullptr : &design, &laid);
    // A removal that meets no voxel and finds no laid wall next to its region to finish.
    if (a.roi.empty() && !a.makes_gcode) a.note = "nothing to remove in this state";
  }
  return a;
}

// What deposits laid that no removal has finished, after action `a` (`laid`: before it):
// a deposit adds its region of influence (the raw stock is no deposit); a removal takes
// what it cut and, when it finishes walls, the material next to its region.
geometry::Solid laid_after(geometry::Solid laid, const plan::PlanFilePrimitive& p, const ExportedAction& a, bool finishes) {
  if (p.raw_stock()) return laid;
  if (p.mode == config::Mode::Additive) return geometry::unite(laid, a.roi);
  if (laid.empty()) return laid;
  laid = geometry::subtract(laid, a.roi);
  if (finishes) {
    // Only round what was laid: the region may span the whole domain.
    const geometry::IndexBox b = laid.bounding_box();
    const geometry::IndexBox near{{b.lo.x - 2, b.lo.y - 2, b.lo.z - 2}, {b.hi.x + 2, b.hi.y + 2, b.hi.z + 2}};
    laid = geometry::subtract(laid, geometry::dilate(p.region, geometry::Ball{1.5 * p.region.lattice().voxel_size}, near));
  }
  return laid;
}

// Whether removal `p` finishes the walls next to its region on the STL (toolpaths/pocket_path.hpp).
bool finishes_walls(const plan::PlanFilePrimitive& p, const config::Machine& machine, const ExportOptions& options) {
  if (p.mode != config::Mode::Subtractive || !options.pocket.finish_walls) return false;
  const config::CuttingTool* tool = machine.find_tool(p.tool_number);
  return tool && tool->type == config::ToolType::Flat;
}

// Actions `first`.. of the plan into `out` (which holds those before); `present` is the
// material the first one meets when the material present is fed back, `planned` the
// planned states otherwise.
void export_from(int first, geometry::Solid present, const std::vector<geometry::Solid>& planned,
                 const plan::PlanFile& file, const plan::PlanFilePlan& plan, const config::Machine& machine,
                 const ExportOptions& options, const MaterialAfter& material_after, PlanExport& out) {
  const int n = int(plan.actions.size());
  const geometry::IndexBox simulated = plan::simulated_domain(file, plan, machine);
  DesignFrames design(file.design_mesh);
  geometry::Solid laid = first > 0 ? out.actions.at(std::size_t(first) - 1).laid : geometry::Solid(file.lattice, {});
  for (int k = first; k < n; ++k) {
    if (options.progress) options.progress(k + 1, n);
    const plan::PlanFilePrimitive& p = file.primitives[std::size_t(plan.actions[std::size_t(k)].primitive)];
    if (p.raw_stock()) out.raw_stock = p.label;
    const geometry::Solid* planned_before = planned.empty() ? nullptr : &planned[std::size_t(k)];
    ExportedAction a = material_after
                           ? make_action(k, present, nullptr, simulated, file, plan, machine, options, design, laid,
                                         planned_before)
                           : make_action(k, planned[std::size_t(k)], &planned[std::size_t(k) + 1], simulated, file, plan,
                                         machine, options, design, laid);
    laid = laid_after(std::move(laid), p, a, finishes_walls(p, machine, options));
    a.laid = laid;
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
  DesignFrames design(file.design_mesh);
  const auto primitive = [&](int j) -> const plan::PlanFilePrimitive& {
    return file.primitives.at(std::size_t(plan.actions[std::size_t(j)].primitive));
  };
  // What the actions before it laid, from their regions of influence in the planned states.
  geometry::Solid laid(file.lattice, {});
  for (int j = 0; j < k; ++j) {
    ExportedAction before;
    before.roi = primitive(j).mode == config::Mode::Additive ? subtract(primitive(j).region, planned[std::size_t(j)])
                                                             : intersect(planned[std::size_t(j)], primitive(j).region);
    laid = laid_after(std::move(laid), primitive(j), before, finishes_walls(primitive(j), machine, options));
  }
  ExportedAction a = make_action(k, planned[std::size_t(k)], &planned[std::size_t(k) + 1],
                                 plan::simulated_domain(file, plan, machine), file, plan, machine, options, design, laid);
  a.laid = laid_after(std::move(laid), primitive(k), a, finishes_walls(primitive(k), machine, options));
  return a;
}

}  // namespace hybridctl::toolpaths
