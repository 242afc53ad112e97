#include "sim/replay.hpp"

#include <map>
#include <memory>

#include "common/error.hpp"
#include "gcode/interpreter.hpp"
#include "gcode/setup_frame.hpp"
#include "sim/instrument.hpp"

namespace hybridctl::sim {
namespace {

using geometry::IndexBox;
using geometry::Solid;

// `solid` turned into (or out of) a setup's work frame, stored over the turned `domain`
// so the simulated world keeps its extent.
Solid turned(const Solid& solid, const IndexBox& domain, config::Approach approach, bool to_work) {
  const IndexBox box = to_work ? gcode::part_to_work(domain, solid.lattice(), approach)
                               : gcode::work_to_part(domain, solid.lattice(), approach);
  const Solid t = to_work ? gcode::part_to_work(solid, approach) : gcode::work_to_part(solid, approach);
  Solid out(solid.lattice(), box);
  t.for_each_voxel([&](geometry::Index3 v) {
    if (box.contains(v)) out.set(v);
  });
  return out;
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

ReplayResult replay_program(std::string_view text, const config::Machine& machine, const Solid& stock,
                            const ReplayOptions& options, const std::string& file_name) {
  ReplayResult result;
  const IndexBox domain = stock.storage_box();
  gcode::Interpreter interp(machine, file_name);

  // The instruments by T number.
  std::map<int, Cutter> cutters;
  std::map<int, Bead> beads;
  for (const auto& t : machine.tools) cutters.emplace(t.number, cutter_of(t));
  for (std::size_t i = 0; i < machine.heads.size(); ++i) {
    const int number = machine.heads[i].tool_number > 0 ? machine.heads[i].tool_number : int(100 + i);
    beads.emplace(number, bead_of(machine.heads[i]));
  }
  auto setup_of = [&](int offset) -> const config::Setup* {
    for (const auto& s : machine.setups)
      if (s.work_offset == offset) return &s;
    return nullptr;
  };

  // The simulation runs in one setup's frame at a time; the stock is carried across.
  Solid part_stock = stock;
  const config::Setup* frame = nullptr;
  std::unique_ptr<MaterialSimulation> sim;
  auto leave_frame = [&] {
    if (!sim) return;
    add(result.report, sim->report());
    part_stock = turned(sim->stock(), gcode::part_to_work(domain, stock.lattice(), frame->approach), frame->approach, false);
    sim.reset();
  };
  auto enter_frame = [&](const config::Setup* setup) {
    if (sim && frame == setup) return;
    leave_frame();
    frame = setup;
    std::optional<Solid> guard;
    if (options.protected_region) guard = turned(*options.protected_region, domain, setup->approach, true);
    sim = std::make_unique<MaterialSimulation>(turned(part_stock, domain, setup->approach, true), std::move(guard),
                                               options.simulation);
  };

  const config::Setup* current = setup_of(54);
  std::size_t start = 0;
  int number = 0;
  while (start <= text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(start, end - start);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    ++number;
    start = end + 1;
    if (end == text.size() && line.empty()) break;
    ++result.lines;
    try {
      const gcode::LineResult& r = interp.execute_line(line, number);
      for (const gcode::Motion& m : r.motions) {
        ++result.motions;
        if (m.work_offset != 53) current = setup_of(m.work_offset);
        if (!current) continue;  // an offset no setup has: nothing to place the part by
        const int tool = m.tool;
        const auto cutter = cutters.find(tool);
        const auto bead = beads.find(tool);
        if (cutter == cutters.end() && bead == beads.end()) continue;  // empty spindle
        enter_frame(current);
        const auto& o = current->work_origin;
        auto work = [&](const geometry::Vec3& p) { return geometry::Vec3{p.x - o[0], p.y - o[1], p.z - o[2]}; };
        MaterialMove move;
        move.motion = m.kind == gcode::MotionKind::Rapid ? Motion::Rapid
                      : m.kind == gcode::MotionKind::Feed ? Motion::Linear
                      : m.kind == gcode::MotionKind::ArcCw ? Motion::ArcCw
                                                            : Motion::ArcCcw;
        if (m.is_arc() && m.plane != gcode::Plane::XY) {
          result.errors.push_back(file_name + ":" + std::to_string(m.line) +
                                  ": an arc outside the XY plane: the material simulation runs XY arcs only");
          continue;
        }
        move.from = work(m.from_machine);
        move.to = work(m.to_machine);
        move.centre = work(m.centre_machine);
        move.process_on = m.deposition;
        move.line = m.line;
        if (cutter != cutters.end()) {
          sim->cut(cutter->second, move);
        } else {
          sim->deposit(bead->second, move);
        }
        ++result.simulated;
      }
    } catch (const InputError& e) {
      result.errors.push_back(e.what());
    }
  }
  leave_frame();
  result.stock = std::move(part_stock);
  if (!(result.stock.storage_box() == domain)) {
    Solid out(stock.lattice(), domain);
    result.stock.for_each_voxel([&](geometry::Index3 v) {
      if (domain.contains(v)) out.set(v);
    });
    result.stock = std::move(out);
  }
  return result;
}

}  // namespace hybridctl::sim
