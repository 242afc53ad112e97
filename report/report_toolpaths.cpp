#include "report/report_toolpaths.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <map>
#include <numbers>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <tbb/task_group.h>

#include "gcode/check.hpp"
#include "gcode/post.hpp"
#include "toolpaths/plan_export.hpp"
#include "toolpaths/setup_frame.hpp"

namespace hybridctl::report {
namespace {

using gcode::MoveKind;
using gcode::PathMove;
using geometry::Vec3;

double distance(const Vec3& a, const Vec3& b) { return std::hypot(a.x - b.x, a.y - b.y, a.z - b.z); }

// An arc in the work frame's XY plane as chords of at most 10 degrees (z runs linearly:
// a helix when the ends differ in z).
std::vector<Vec3> arc_points(const Vec3& from, const PathMove& m) {
  const double r = std::hypot(from.x - m.centre.x, from.y - m.centre.y);
  const double a0 = std::atan2(from.y - m.centre.y, from.x - m.centre.x);
  double a1 = std::atan2(m.to.y - m.centre.y, m.to.x - m.centre.x);
  const bool ccw = m.kind == MoveKind::ArcCcw;
  double sweep = ccw ? a1 - a0 : a0 - a1;
  while (sweep <= 1e-12) sweep += 2 * std::numbers::pi;
  const int pieces = std::max(2, int(std::ceil(sweep / (std::numbers::pi / 18))));
  std::vector<Vec3> points;
  for (int i = 1; i <= pieces; ++i) {
    const double t = double(i) / pieces, a = a0 + (ccw ? 1 : -1) * sweep * t;
    points.push_back(i == pieces ? m.to
                                 : Vec3{m.centre.x + r * std::cos(a), m.centre.y + r * std::sin(a),
                                        from.z + (m.to.z - from.z) * t});
  }
  return points;
}

class PathBuilder {
 public:
  PathBuilder(ActionPath& path, config::Approach approach) : path_(path), approach_(approach) {}

  void move(const Vec3& from, const PathMove& m) {
    const SegmentKind kind = m.kind == MoveKind::Rapid ? SegmentKind::Rapid
                             : m.process_on            ? SegmentKind::Process
                                                       : SegmentKind::Feed;
    if (kind == SegmentKind::Process) enter_layer(m.to.z);
    Vec3 at = from;
    const std::vector<Vec3> ends =
        m.kind == MoveKind::ArcCw || m.kind == MoveKind::ArcCcw ? arc_points(from, m) : std::vector<Vec3>{m.to};
    for (const Vec3& to : ends) {
      segment(at, to, kind);
      at = to;
    }
  }

 private:
  // A process move at another Z than the current layer's starts the next layer.
  void enter_layer(double z) {
    if (path_.layer_z.empty() || std::abs(layer_at_ - z) > 1e-6) {
      if (!path_.layer_z.empty()) ++layer_;
      path_.layer_z.push_back(float(z));
      layer_at_ = z;
    }
  }
  void segment(const Vec3& a, const Vec3& b, SegmentKind kind) {
    for (const Vec3& p : {a, b}) {
      const Vec3 q = toolpaths::work_to_part(p, approach_);
      path_.points.insert(path_.points.end(), {float(q.x), float(q.y), float(q.z)});
    }
    path_.kinds.push_back(kind);
    path_.layers.push_back(std::uint16_t(std::min(layer_, 65535)));
    const double length = distance(a, b);
    (kind == SegmentKind::Rapid ? path_.rapid_length : kind == SegmentKind::Feed ? path_.feed_length
                                                                                 : path_.process_length) += length;
  }

  ActionPath& path_;
  config::Approach approach_;
  int layer_ = 0;
  double layer_at_ = 0;  // the current layer's Z, unrounded
};

config::Approach approach_of(const config::Machine& machine, const std::string& setup_name) {
  const config::Setup* setup = machine.find_setup(setup_name);
  return setup ? setup->approach : config::Approach::PlusZ;
}

ActionPath action_path(const toolpaths::ExportedAction& exported, const config::Machine& machine) {
  ActionPath path;
  path.step = exported.step;
  path.primitive = exported.primitive;
  path.makes_gcode = exported.makes_gcode;
  path.note = exported.note;
  if (!exported.makes_gcode) return path;
  const gcode::ActionProgram& program = exported.program;
  const gcode::Toolpath& tp = program.path;
  path.additive = program.additive;
  path.instrument = tp.instrument;
  path.setup = tp.setup;
  path.tool_number = tp.tool_number;
  path.warnings = tp.warnings;
  PathBuilder builder(path, approach_of(machine, tp.setup));
  Vec3 at = tp.start;
  for (const PathMove& m : tp.moves) {
    builder.move(at, m);
    at = m.to;
  }
  // The time model is the one `gcode check` and `export` print: the action's own program's
  // motion and dwell, as `plan` and `export` print it per action (the changes are the plan's).
  const std::string text = gcode::write_action(program, machine);
  const gcode::TimeEstimate time = gcode::check_program(text, machine, "action " + std::to_string(path.step)).time;
  path.cycle_s = time.motion + time.dwell;
  return path;
}

// Where the tool is after each line of the plan's program.
std::vector<Vec3> line_positions(const std::vector<gcode::ActionProgram>& programs, const config::Machine& machine) {
  std::vector<Vec3> out;
  if (programs.empty()) return out;
  const gcode::PostedProgram posted = gcode::post_program(programs, machine);
  Vec3 at = toolpaths::work_to_part(programs.front().path.start, approach_of(machine, programs.front().path.setup));
  for (const gcode::LineOrigin& origin : posted.origins) {
    if (origin.action && origin.move && *origin.action < programs.size()) {
      const gcode::Toolpath& tp = programs[*origin.action].path;
      if (*origin.move < tp.moves.size()) at = toolpaths::work_to_part(tp.moves[*origin.move].to, approach_of(machine, tp.setup));
    }
    out.push_back(at);
  }
  return out;
}

// One distinct action: the first plan that has it, and its place there.
struct ActionJob {
  std::size_t plan = 0, action = 0;
  double cost = 0;
  ActionPath path;
  gcode::ActionProgram program;  // when path.makes_gcode
  std::string error;
};

}  // namespace

std::vector<PlanPaths> plan_paths(const plan::PlanFile& file, const std::vector<std::vector<geometry::Solid>>& states,
                                  const config::Machine& machine) {
  std::vector<ActionJob> jobs;
  std::map<std::vector<int>, std::size_t> job_of;           // by the primitives up to the action
  std::vector<std::vector<std::size_t>> plan_jobs(file.plans.size());
  for (std::size_t k = 0; k < file.plans.size(); ++k) {
    std::vector<int> prefix;
    for (std::size_t a = 0; a < file.plans[k].actions.size(); ++a) {
      prefix.push_back(file.plans[k].actions[a].primitive);
      const auto [it, fresh] = job_of.emplace(prefix, jobs.size());
      if (fresh) jobs.push_back({k, a, file.plans[k].actions[a].cost, {}, {}, {}});
      plan_jobs[k].push_back(it->second);
    }
  }
  std::vector<std::size_t> order(jobs.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return jobs[a].cost > jobs[b].cost; });
  // Each worker takes the next job in that order (a parallel_for would split the range
  // and might leave the longest job to the end).
  std::atomic<std::size_t> next{0};
  tbb::task_group workers;
  for (int w = 0; w < std::max(1, tbb::this_task_arena::max_concurrency()); ++w)
    workers.run([&] {
      for (std::size_t i = next++; i < order.size(); i = next++) {
        ActionJob& job = jobs[order[i]];
        try {
          const toolpaths::ExportedAction exported = toolpaths::export_planned_action(
              file, file.plans[job.plan], int(job.action), states.at(job.plan), machine);
          job.path = action_path(exported, machine);
          if (exported.makes_gcode) job.program = exported.program;
        } catch (const std::exception& e) {  // the plan is still shown, without its toolpaths
          job.error = e.what();
        }
      }
    });
  workers.wait();

  std::vector<PlanPaths> out(file.plans.size());
  tbb::parallel_for(std::size_t(0), out.size(), [&](std::size_t k) {
    std::vector<gcode::ActionProgram> programs;
    for (const std::size_t j : plan_jobs[k]) {
      if (!jobs[j].error.empty() && out[k].error.empty()) out[k].error = jobs[j].error;
      out[k].actions.push_back(jobs[j].path);  // the same step in every plan that has it
      if (out[k].actions.back().makes_gcode) programs.push_back(jobs[j].program);
    }
    if (!out[k].error.empty()) {
      out[k].actions.clear();
      return;
    }
    out[k].line_positions = line_positions(programs, machine);
  });
  return out;
}

}  // namespace hybridctl::report
