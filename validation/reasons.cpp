// Why an executed plan does not make the part, located: per action and G-code line, in
// the part frame (docs/validation.md lists the kinds).

#include <algorithm>
#include <iterator>
#include <map>
#include <utility>

#include "common/error.hpp"
#include "common/number_text.hpp"
#include "toolpaths/setup_frame.hpp"
#include "validation/execution.hpp"

namespace hybridctl::validation {
namespace {

using plan::RejectionReason;

const config::Setup* setup_named(const config::Machine& machine, const std::string& name) {
  for (const config::Setup& s : machine.setups)
    if (s.name == name) return &s;
  return nullptr;
}

// A point of an action's work frame in the part frame.
geometry::Vec3 in_part_frame(const geometry::Vec3& work, const config::Machine& machine, const std::string& setup) {
  const config::Setup* s = setup_named(machine, setup);
  return s ? toolpaths::work_to_part(work, s->approach) : work;
}

// Defects the toolpath generators found (the part will be wrong as the path stands).
void add_path_defects(const Execution& run, const config::Machine& machine, std::vector<RejectionReason>& out) {
  for (const toolpaths::ExportedAction& a : run.exported.actions) {
    int line = 0;  // the action's heading, when it made G-code
    for (const gcode::ProgramAction& p : run.program.actions)
      if (p.number == a.step) line = int(p.first_line);
    for (const gcode::PathDefect& d : a.program.path.defects)
      out.push_back({d.kind, a.step, line, d.message, in_part_frame(d.where, machine, a.program.path.setup)});
  }
}

// One reason per incident kind and action: the first incident, with how many there were.
void add_incidents(const Execution& run, const config::Machine& machine, std::vector<RejectionReason>& out) {
  struct Group {
    const sim::Incident* first = nullptr;
    int count = 0;
    double volume = 0;
  };
  std::map<std::pair<int, int>, Group> groups;  // (action, kind) in order
  for (const sim::Incident& i : run.report.incidents) {
    const gcode::ProgramAction* a = run.program.action_at(std::uint32_t(i.line));
    Group& g = groups[{a ? a->number : 0, int(i.kind)}];
    if (!g.first) g.first = &i;
    ++g.count;
    g.volume += i.volume;
  }
  for (const auto& [key, g] : groups) {
    const sim::Incident& i = *g.first;
    const gcode::ProgramAction* a = run.program.action_at(std::uint32_t(i.line));
    const geometry::Vec3 middle{(i.region.min.x + i.region.max.x) / 2, (i.region.min.y + i.region.max.y) / 2,
                                (i.region.min.z + i.region.max.z) / 2};
    std::string message = std::string(sim::to_string(i.kind)) + ": " + std::to_string(g.count) + " move" +
                          (g.count == 1 ? "" : "s") + ", " + fixed_number(g.volume, 1) + " mm^3 in all; the first: " +
                          sim::describe(i);
    out.push_back({reason_kind(i.kind), key.first, i.line, std::move(message),
                   a ? in_part_frame(middle, machine, a->setup) : middle});
  }
}

// The part as built against the design, both ways, with the tolerance.
void add_deviation(const Execution& run, double tolerance, double voxel, std::vector<RejectionReason>& out) {
  const plan::Deviation& d = run.deviation;
  if (d.within_tolerance) return;
  const double limit = plan::judged_limit(tolerance, voxel);
  // The two-sided test that decides `within_tolerance` (plan/deviation.hpp) names the
  // reasons: a fin left out leaves few voxels empty, none deep, yet the design's surface at
  // its tip is far from the part made.
  if (d.worst_missing > limit)
    out.push_back({"missing_material", 0, 0,
                   "as built, " + fixed_number(d.under_volume, 1) +
                       " mm^3 of the design is missing; the design's surface lies up to " +
                       fixed_number(d.worst_missing, 2) + " mm from the part made; tolerance " +
                       trimmed_number(tolerance, 3) + " mm",
                   d.worst_missing_at});
  if (d.worst_out > limit)
    out.push_back({"excess_material", 0, 0,
                   "as built, " + fixed_number(d.over_volume, 1) +
                       " mm^3 of material lies outside the design; the part's surface (or a hole the design does not "
                       "have) lies up to " +
                       fixed_number(d.worst_out, 2) + " mm from the design's; tolerance " + trimmed_number(tolerance, 3) +
                       " mm",
                   d.worst_out_at});
}

}  // namespace

std::string reason_kind(sim::IncidentKind kind) {
  switch (kind) {
    case sim::IncidentKind::RapidIntoMaterial: return "rapid_into_material";
    case sim::IncidentKind::BodyCollision: return "body_collision";
    case sim::IncidentKind::Gouge: return "gouge";
    case sim::IncidentKind::UnsupportedDeposition: return "unsupported_deposit";
    case sim::IncidentKind::DepositionOutsideDomain: return "deposit_outside_domain";
  }
  // A kind added later: its words joined by underscores.
  std::string name(sim::to_string(kind));
  for (char& c : name)
    if (c == ' ') c = '_';
  return name;
}

std::string describe_reasons(const std::vector<RejectionReason>& reasons, std::size_t shown) {
  std::string out;
  for (std::size_t i = 0; i < reasons.size() && i < shown; ++i)
    out += "  " + reasons[i].kind + ": " + plan::describe(reasons[i]) + "\n";
  if (reasons.size() > shown) out += "  ... and " + std::to_string(reasons.size() - shown) + " more\n";
  return out;
}

Execution require_proven(const plan::PlanFile& file, const plan::PlanFilePlan& plan,
                         const config::Machine& machine, const ExecutionOptions& options, const std::string& what) {
  Execution run = execute_plan(file, plan, machine, options);
  // Every reason refuses: a path that skips what it should make, a rapid or a body into
  // material, a cut into the part, a line the machine refuses, a bead over air that falls,
  // a part out of tolerance. Each means the part comes off the machine wrong or the
  // machine is put at risk.
  if (!run.reasons.empty())
    throw NotManufacturableError(what + " is not safe to run or does not make the part when executed from the raw "
                                 "stock (" + std::to_string(run.reasons.size()) + " reason" +
                                 (run.reasons.size() == 1 ? "" : "s") + "); nothing written:\n" +
                                 describe_reasons(run.reasons));
  return run;
}

std::vector<RejectionReason> rejection_reasons(const Execution& run, const plan::PlanFile& file,
                                               const config::Machine& machine) {
  std::vector<RejectionReason> out;
  add_path_defects(run, machine, out);
  add_incidents(run, machine, out);
  for (const std::string& e : run.errors) out.push_back({"refused_line", 0, 0, e, std::nullopt});
  if (run.stopped_after == 0) add_deviation(run, file.band(), file.lattice.voxel_size, out);  // stopped early: not measured
  return out;
}

}  // namespace hybridctl::validation
