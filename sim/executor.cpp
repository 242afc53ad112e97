#include "sim/executor.hpp"

#include <map>

#include "common/error.hpp"
#include "gcode/check.hpp"
#include "instruments/bead.hpp"
#include "toolpaths/setup_frame.hpp"
#include "sim/instrument.hpp"

namespace hybridctl::sim {
namespace {

using geometry::IndexBox;
using geometry::Solid;

// `solid` turned into (or out of) a setup's work frame, stored over the turned `domain`
// so the simulated world keeps its extent.
Solid turned(const Solid& solid, const IndexBox& domain, config::Approach approach, bool to_work) {
  if (approach == config::Approach::PlusZ) return solid;
  const IndexBox box = to_work ? toolpaths::part_to_work(domain, solid.lattice(), approach)
                               : toolpaths::work_to_part(domain, solid.lattice(), approach);
  const Solid t = to_work ? toolpaths::part_to_work(solid, approach) : toolpaths::work_to_part(solid, approach);
  return copied_onto(t, solid.lattice(), box);
}

void add(SimulationReport& total, const SimulationReport& part) {
  total.moves += part.moves;
  total.removed += part.removed;
  total.gouge += part.gouge;
  total.deposited += part.deposited;
  total.overlap += part.overlap;
  total.outside += part.outside;
  total.collision += part.collision;
  total.rapid_contact += part.rapid_contact;
  total.incidents.insert(total.incidents.end(), part.incidents.begin(), part.incidents.end());
}

}  // namespace

struct ProgramExecutor::Impl {
  const config::Machine& machine;
  std::string file_name;
  ExecutorOptions options;
  gcode::Interpreter interp;
  std::map<int, Cutter> cutters;
  std::map<int, Bead> beads;
  // The stock lives in the part frame between setups and in the active setup's frame
  // inside `sim` while motions run there.
  std::optional<Solid> part_stock;
  IndexBox domain;
  const config::Setup* frame = nullptr;
  std::unique_ptr<MaterialSimulation> sim;
  SimulationReport finished;  // totals of simulations already left
  const config::Setup* current = nullptr;

  Impl(const config::Machine& m, std::string name, ExecutorOptions o, gcode::InterpreterOptions io)
      : machine(m), file_name(name), options(std::move(o)), interp(m, std::move(name), io) {
    for (const auto& t : m.tools) cutters.emplace(t.number, cutter_of(t));
    for (std::size_t i = 0; i < m.heads.size(); ++i) beads.emplace(instruments::head_tool_number(m, i), bead_of(m.heads[i]));
    if (options.stock) {
      // Moved out: a snapshot need not carry the start as well.
      part_stock = std::move(*options.stock);
      options.stock.reset();
      domain = part_stock->storage_box();
    }
    current = setup_of(54);
  }
  // A deep copy (the simulation too); the machine, and the setups `frame` and `current`
  // point into, are shared.
  Impl(const Impl& o)
      : machine(o.machine),
        file_name(o.file_name),
        options(o.options),
        interp(o.interp),
        cutters(o.cutters),
        beads(o.beads),
        part_stock(o.part_stock),
        domain(o.domain),
        frame(o.frame),
        sim(o.sim ? std::make_unique<MaterialSimulation>(*o.sim) : nullptr),
        finished(o.finished),
        current(o.current) {}

  const config::Setup* setup_of(int offset) const {
    for (const auto& s : machine.setups)
      if (s.work_offset == offset) return &s;
    return nullptr;
  }
  void leave_frame() {
    if (!sim) return;
    add(finished, sim->report());
    part_stock = turned(sim->stock(), toolpaths::part_to_work(domain, part_stock->lattice(), frame->approach), frame->approach,
                        false);
    sim.reset();
  }
  void enter_frame(const config::Setup* setup) {
    if (sim && frame == setup) return;
    leave_frame();
    frame = setup;
    std::optional<Solid> guard;
    if (options.protected_region) guard = turned(*options.protected_region, domain, setup->approach, true);
    sim = std::make_unique<MaterialSimulation>(turned(*part_stock, domain, setup->approach, true), std::move(guard),
                                               options.simulation);
  }
  bool is_head(int tool) const { return beads.count(tool) > 0; }
  bool known(int tool) const { return tool == 0 || cutters.count(tool) || beads.count(tool); }
};

ProgramExecutor::ProgramExecutor(const config::Machine& machine, std::string file_name, ExecutorOptions options,
                                 gcode::InterpreterOptions interpreter)
    : impl_(std::make_unique<Impl>(machine, std::move(file_name), std::move(options), interpreter)) {}
ProgramExecutor::ProgramExecutor(const Snapshot& snapshot) : impl_(std::make_unique<Impl>(*snapshot.impl_)) {}
ProgramExecutor::~ProgramExecutor() = default;

ProgramExecutor::Snapshot::Snapshot() = default;
ProgramExecutor::Snapshot::~Snapshot() = default;
ProgramExecutor::Snapshot::Snapshot(Snapshot&&) noexcept = default;
ProgramExecutor::Snapshot& ProgramExecutor::Snapshot::operator=(Snapshot&&) noexcept = default;

ProgramExecutor::Snapshot ProgramExecutor::snapshot() const {
  Snapshot s;
  s.impl_ = std::make_unique<Impl>(*impl_);
  return s;
}

std::size_t ProgramExecutor::Snapshot::bytes() const {
  if (!impl_) return 0;
  const auto solid = [](const Solid& s) {
    const IndexBox b = s.storage_box();
    return sizeof(Solid) + (b.empty() ? 0 : std::size_t(s.words_per_row()) * std::size_t(b.hi.y - b.lo.y) *
                                                std::size_t(b.hi.z - b.lo.z) * sizeof(std::uint64_t));
  };
  const Impl& i = *impl_;
  std::size_t n = sizeof(Impl) + i.finished.incidents.size() * sizeof(Incident);
  if (i.part_stock) n += solid(*i.part_stock);
  if (i.options.protected_region) n += solid(*i.options.protected_region);
  if (i.sim) {
    n += sizeof(MaterialSimulation) + solid(i.sim->stock()) + i.sim->report().incidents.size() * sizeof(Incident);
    if (i.sim->protected_region()) n += solid(*i.sim->protected_region());
  }
  return n;
}
ProgramExecutor::ProgramExecutor(ProgramExecutor&&) noexcept = default;
ProgramExecutor& ProgramExecutor::operator=(ProgramExecutor&&) noexcept = default;

const gcode::ModalState& ProgramExecutor::state() const { return impl_->interp.state(); }

void ProgramExecutor::set_protected_region(std::optional<Solid> protected_region) {
  Impl& i = *impl_;
  i.options.protected_region = std::move(protected_region);
  if (!i.sim) return;  // enter_frame turns it into the next setup's frame
  std::optional<Solid> guard;
  if (i.options.protected_region) guard = turned(*i.options.protected_region, i.domain, i.frame->approach, true);
  i.sim->set_protected_region(std::move(guard));
}

Solid ProgramExecutor::stock() const {
  Impl& i = *impl_;
  if (!i.part_stock) return Solid();
  if (!i.sim) return *i.part_stock;
  return turned(i.sim->stock(), toolpaths::part_to_work(i.domain, i.part_stock->lattice(), i.frame->approach),
                i.frame->approach, false);
}

SimulationReport ProgramExecutor::report() const {
  SimulationReport r = impl_->finished;
  if (impl_->sim) add(r, impl_->sim->report());
  return r;
}

LineOutcome ProgramExecutor::execute_line(std::string_view text, int number) {
  Impl& i = *impl_;
  LineOutcome out;
  const auto where = [&] { return i.file_name + ":" + std::to_string(number) + ": "; };
  // A line refused by an interlock or a soft limit leaves the machine as it was: the
  // interpreter's state is put back.
  const gcode::ModalState before = i.interp.state();
  struct Refuse {
    Impl& i;
    const gcode::ModalState& before;
    LineOutcome& out;
    LineOutcome& operator()(Stop stop, std::string message) {
      i.interp.restore(before);
      out.stop = stop;
      out.message = std::move(message);
      out.motions.clear();
      return out;
    }
  } refuse{i, before, out};
  try {
    const gcode::LineResult& r = i.interp.execute_line(text, number);
    out.events = r.events;
    out.motions = r.motions;
  } catch (const InputError& e) {
    out.stop = Stop::GcodeError;
    out.message = e.what();
    return out;
  }
  // Interlocks a controller checks before it moves.
  int tool = before.tool;
  bool spindle = before.spindle != gcode::SpindleState::Off, depositing = before.any_deposition();
  for (const gcode::Event& e : out.events) {
    if (e.kind == gcode::EventKind::ToolChange) {
      if (!i.known(e.tool))
        return refuse(Stop::ToolNotInMagazine, where() + "T" + std::to_string(e.tool) + " is not in the magazine (no such tool or head)");
      tool = e.tool;
    } else if (e.kind == gcode::EventKind::SpindleStart) {
      spindle = true;
    } else if (e.kind == gcode::EventKind::SpindleStop) {
      spindle = false;
    } else if (e.kind == gcode::EventKind::DepositionOn) {
      if (!i.is_head(tool))
        return refuse(Stop::DepositionWithoutHead, where() + "deposition switched on with " +
                                                       (tool ? "cutting tool T" + std::to_string(tool) : std::string("no tool")) +
                                                       " in the spindle");
      depositing = true;
    } else if (e.kind == gcode::EventKind::DepositionOff) {
      depositing = false;
    } else if (e.kind == gcode::EventKind::Dwell) {
      out.seconds += e.value;
    }
    if (spindle && depositing) return refuse(Stop::SpindleDepositionConflict, where() + "spindle and deposition on at once");
  }
  // Soft limits: checked for the whole line before anything moves.
  for (const gcode::Motion& m : out.motions)
    if (auto violation = gcode::envelope_violation(m, i.machine.envelope))
      return refuse(Stop::EnvelopeViolation, where() + *violation);
  std::vector<gcode::Motion> done;
  for (const gcode::Motion& m : out.motions) {
    out.seconds += gcode::motion_time(m, i.machine.envelope);
    done.push_back(m);
    if (m.work_offset != 53) i.current = i.setup_of(m.work_offset);
    if (!i.part_stock || !i.current) continue;
    const auto cutter = i.cutters.find(m.tool);
    const auto bead = i.beads.find(m.tool);
    if (cutter == i.cutters.end() && bead == i.beads.end()) continue;  // empty spindle
    if (m.is_arc() && m.plane != gcode::Plane::XY) continue;  // the material simulation runs XY arcs only
    i.enter_frame(i.current);
    const MaterialMove move = material_move(m, *i.current);
    const MoveReport r = cutter != i.cutters.end() ? i.sim->cut(cutter->second, move) : i.sim->deposit(bead->second, move);
    out.incidents.insert(out.incidents.end(), r.incidents.begin(), r.incidents.end());
    // A crash stops the machine once it has happened; a bead that fell does not (the
    // controller warns, sim/controller.cpp).
    for (const Incident& inc : r.incidents) {
      const bool nozzle = inc.kind == IncidentKind::BodyCollision && bead != i.beads.end();
      if ((inc.kind == IncidentKind::RapidIntoMaterial || nozzle) && out.stop == Stop::None) {
        out.stop = nozzle ? Stop::NozzleCollision : Stop::RapidIntoMaterial;
        out.message = where() + describe(inc);
      }
    }
    if (out.stop != Stop::None) break;
  }
  out.motions = std::move(done);
  return out;
}

}  // namespace hybridctl::sim
