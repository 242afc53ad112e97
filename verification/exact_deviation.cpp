#include "verification/exact_deviation.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <map>

#include <boost/container/small_vector.hpp>
#include <tbb/parallel_for.h>

#include "common/error.hpp"
#include "gcode/interpreter.hpp"
#include "instruments/bead.hpp"
#include "instruments/cutter.hpp"
#include "sim/moves.hpp"
#include "sim/sweep.hpp"
#include "toolpaths/setup_frame.hpp"
#include "verification/line_sweep.hpp"
#include "verification/vector_index.hpp"

namespace hybridctl::verification {
namespace {

using geometry::Vec3;

// What made a boundary of material along a vector: the start stock, or one move.
struct Op {
  int line = 0;
  int action = 0;  // 1-based; 0: the start stock
  int head = -1;   // index into machine.heads for a bead laid; -1 for a cut
};

// Shorter than this along a vector (mm), a span holds no material.
constexpr double kNoLength = 1e-9;

// One interval of material along a vector, with the operation that made each end.
struct Run {
  double lo = 0, hi = 0;
  int lo_op = 0, hi_op = 0;
};
// Inline: nearly every vector holds one or two runs, and a sweep that reaches a vector
// then finds them where it finds the vector's other state, without a second fetch.
using Runs = boost::container::small_vector<Run, 2>;

void subtract(Runs& runs, Span s, int op, Runs& scratch) {
  scratch.clear();
  bool changed = false;
  for (const Run& r : runs) {
    if (s.hi <= r.lo || s.lo >= r.hi) {
      scratch.push_back(r);
      continue;
    }
    changed = true;
    if (r.lo < s.lo) scratch.push_back({r.lo, s.lo, r.lo_op, op});
    if (s.hi < r.hi) scratch.push_back({s.hi, r.hi, op, r.hi_op});
  }
  if (changed) runs.swap(scratch);
}

void unite(Runs& runs, Span s, int op, Runs& scratch) {
  scratch.clear();
  Run added{s.lo, s.hi, op, op};
  bool placed = false;
  for (const Run& r : runs) {
    if (r.hi < added.lo) {
      scratch.push_back(r);
    } else if (r.lo > added.hi) {
      if (!placed) scratch.push_back(added), placed = true;
      scratch.push_back(r);
    } else {
      if (r.lo < added.lo) added.lo = r.lo, added.lo_op = r.lo_op;
      if (r.hi > added.hi) added.hi = r.hi, added.hi_op = r.hi_op;
    }
  }
  if (!placed) scratch.push_back(added);
  runs.swap(scratch);
}

Vec3 along(const SurfaceSample& s, double t) {
  return {s.point.x + t * s.normal.x, s.point.y + t * s.normal.y, s.point.z + t * s.normal.z};
}

// The start stock along a vector: the cubes of its voxels, exactly (the line's crossings
// of the lattice planes cut it into pieces that lie in one voxel each). The caller tells
// an empty stock apart once (Solid::empty() scans the whole grid).
Runs stock_runs(const geometry::Solid& stock, const SurfaceSample& s) {
  Runs runs;
  const geometry::Lattice& l = stock.lattice();
  const double t0 = -s.inward, t1 = s.outward;
  std::vector<double> cuts{t0, t1};
  const double p[3] = {s.point.x, s.point.y, s.point.z}, d[3] = {s.normal.x, s.normal.y, s.normal.z};
  const double o[3] = {l.origin.x, l.origin.y, l.origin.z};
  for (int a = 0; a < 3; ++a) {
    if (std::abs(d[a]) < 1e-12) continue;
    const double u0 = (p[a] + std::min(t0 * d[a], t1 * d[a]) - o[a]) / l.voxel_size;
    const double u1 = (p[a] + std::max(t0 * d[a], t1 * d[a]) - o[a]) / l.voxel_size;
    for (double k = std::ceil(u0); k <= u1; ++k) cuts.push_back((o[a] + k * l.voxel_size - p[a]) / d[a]);
  }
  std::sort(cuts.begin(), cuts.end());
  for (std::size_t i = 0; i + 1 < cuts.size(); ++i) {
    const double a = std::max(cuts[i], t0), b = std::min(cuts[i + 1], t1);
    if (!(b > a)) continue;
    const Vec3 m = along(s, 0.5 * (a + b));
    const geometry::Index3 v{int(std::floor((m.x - l.origin.x) / l.voxel_size)),
                             int(std::floor((m.y - l.origin.y) / l.voxel_size)),
                             int(std::floor((m.z - l.origin.z) / l.voxel_size))};
    if (!stock.contains(v)) continue;
    if (!runs.empty() && std::abs(runs.back().hi - a) < 1e-12) runs.back().hi = b;
    else runs.push_back({a, b, 0, 0});
  }
  return runs;
}

struct Instrument {
  std::vector<sim::ConvexPiece> pieces;
  int head = -1;  // a head's index; -1: a cutter
};

// The box a piece sweeps along a segment, work frame.
geometry::Box3 swept_box(const sim::ConvexPiece& piece, const sim::Segment& s, double ceiling) {
  const double r = piece.reach();
  const double top = std::isfinite(piece.to) ? piece.to : ceiling;
  return {{std::min(s.from.x, s.to.x) - r, std::min(s.from.y, s.to.y) - r, std::min(s.from.z, s.to.z) + piece.from},
          {std::max(s.from.x, s.to.x) + r, std::max(s.from.y, s.to.y) + r, std::max(s.from.z, s.to.z) + top}};
}

class Verifier {
 public:
  Verifier(const DesignSurface& surface, const config::Machine& machine, const geometry::Solid& stock)
      : surface_(surface), machine_(machine), runs_(surface.samples().size()) {
    ops_.push_back({});
    if (!stock.empty())
      for (std::size_t i = 0; i < runs_.size(); ++i) runs_[i] = stock_runs(stock, surface.samples()[i]);
    for (const config::CuttingTool& t : machine.tools)
      instruments_[t.number] = {completed_pieces(sim::pieces_of(instruments::cutter_of(t).cutting)), -1};
    for (std::size_t h = 0; h < machine.heads.size(); ++h)
      instruments_[instruments::head_tool_number(machine, h)] = {sim::pieces_of(instruments::bead_of(machine.heads[h])),
                                                                 int(h)};
  }

  // Records a motion: each of its segments, with the instrument and setup it runs in.
  void move(const gcode::Motion& m, const config::Setup& setup, int action, double arc_tolerance) {
    const auto found = instruments_.find(m.tool);
    if (found == instruments_.end()) return;  // empty spindle
    const Instrument& instrument = found->second;
    const sim::MaterialMove move = sim::material_move(m, setup);
    if (instrument.head >= 0 && !move.process_on) return;
    ops_.push_back({m.line, action, instrument.head});
    for (const sim::Segment& segment : sim::path_segments(move, arc_tolerance))
      steps_.push_back({segment, &instrument, setup.approach, int(ops_.size()) - 1});
  }

  // Replays the recorded segments on the vectors, in program order for each vector. The
  // vectors are independent: two halves go on two threads, each with its own index.
  void sweep() {
    tbb::parallel_for(0, kParts, [&](int part) {
      Runs scratch;
      for (const Step& step : steps_) {
        const FrameIndex& index = surface_.frame(step.approach, std::size_t(part), kParts);
        const bool cuts = step.instrument->head < 0;
        for (const sim::ConvexPiece& piece : step.instrument->pieces)
          index.for_each_near(swept_box(piece, step.segment, ceiling_), [&](const FrameVector& v) {
            Runs& runs = runs_[v.id];
            if (cuts && runs.empty()) return;  // nothing to cut
            // A cut is asked only about the stretch that still holds material.
            const Span span = cuts ? line_in_sweep(piece, step.segment, v.point, v.normal, runs.front().lo, runs.back().hi)
                                   : line_in_sweep(piece, step.segment, v.point, v.normal, v.t0, v.t1);
            // A bead that only touches the vector's end leaves a span of no length there: no
            // material, and a run no cut could take away again (a cut's span ends there too).
            if (span.empty() || (!cuts && span.hi - span.lo < kNoLength)) return;
            if (cuts) subtract(runs, span, step.op, scratch);
            else unite(runs, span, step.op, scratch);
          });
      }
    });
  }

  SurfaceDeviation result(double tolerance) const {
    SurfaceDeviation whole;
    whole.samples.resize(runs_.size());
    plan::ExactDeviation& out = whole.summary;
    out.tolerance = tolerance;
    out.spacing = surface_.options().spacing;
    out.samples = runs_.size();
    double within = 0, total = 0;
    const auto& samples = surface_.samples();
    for (std::size_t i = 0; i < runs_.size(); ++i) {
      const SurfaceSample& s = samples[i];
      const Runs& runs = runs_[i];
      total += s.area;
      // The material under the surface: the last run that starts at or below it.
      const Run* under = nullptr;
      for (const Run& r : runs)
        if (r.lo <= 0) under = &r;
      const Op* surface_op = under ? &ops_[std::size_t(under->hi_op)] : nullptr;
      const bool deposited = surface_op && surface_op->head >= 0;
      const double widen = deposited ? machine_.heads[std::size_t(surface_op->head)].accuracy : 0.0;

      plan::ExactPlace excess, gouge;
      if (!runs.empty() && runs.back().hi > 1e-9) {
        const Run& top = runs.back();
        const Vec3 at = along(s, top.hi);
        excess = place(surface_.distance(at), at, top.hi_op, top.hi >= s.outward - 1e-9);
      }
      // How deep the part made's surface lies under the design's: the top of the material
      // under the surface when it ends below it, or the vector's inner end when there is
      // none. A void enclosed deeper in (the modelled beads' thin slivers between layers at
      // a deposit's fringe) is not the surface; the voxels judge voids.
      double deepest = 1;
      int deepest_op = 0;
      if (!under) {
        deepest = -s.inward;
        deepest_op = runs.empty() ? 0 : runs.front().lo_op;
      } else if (under->hi < -1e-9) {
        deepest = under->hi;
        deepest_op = under->hi_op;
      }
      if (deepest < 0) {
        const Vec3 at = along(s, deepest);
        gouge = place(surface_.distance(at), at, deepest_op, deepest <= -s.inward + 1e-9);
      }
      if (deposited) {
        excess.mm += widen, gouge.mm += widen;
        excess.as_deposited = gouge.as_deposited = true;
        if (!excess.at) excess.at = s.point, excess.action = surface_op->action, excess.line = surface_op->line;
        if (!gouge.at) gouge.at = s.point, gouge.action = surface_op->action, gouge.line = surface_op->line;
      }
      if (excess.mm <= tolerance && gouge.mm <= tolerance) within += s.area;
      whole.samples[i] = {excess.mm, gouge.mm, surface_op ? surface_op->action : 0, deposited};
      if (excess.at && (!out.excess.at || excess.mm > out.excess.mm)) out.excess = excess;
      if (gouge.at && (!out.gouge.at || gouge.mm > out.gouge.mm)) out.gouge = gouge;
    }
    out.within_share = total > 0 ? within / total : 1.0;
    return whole;
  }

  void set_ceiling(double z) { ceiling_ = z; }

 private:
  plan::ExactPlace place(double mm, const Vec3& at, int op, bool at_least) const {
    plan::ExactPlace p;
    p.mm = mm;
    p.at = at;
    p.action = ops_[std::size_t(op)].action;
    p.line = ops_[std::size_t(op)].line;
    p.at_least = at_least;
    return p;
  }

  const DesignSurface& surface_;
  const config::Machine& machine_;
  std::vector<Runs> runs_;
  struct Step {
    sim::Segment segment;
    const Instrument* instrument;
    config::Approach approach;
    int op;
  };
  static constexpr int kParts = 2;
  std::vector<Step> steps_;
  std::vector<Op> ops_;
  std::map<int, Instrument> instruments_;
  double ceiling_ = 1e4;
};

}  // namespace

plan::ExactDeviation verify_program(const DesignSurface& surface, const config::Machine& machine,
                                    const gcode::PostedProgram& program, const geometry::Solid& start_stock,
                                    const VerifyOptions& options) {
  return measure_program(surface, machine, program, start_stock, options).summary;
}

SurfaceDeviation measure_program(const DesignSurface& surface, const config::Machine& machine,
                                 const gcode::PostedProgram& program, const geometry::Solid& start_stock,
                                 const VerifyOptions& options) {
  Verifier verifier(surface, machine, start_stock);
  // Infinite bodies stop at the machine's whole travel: nothing of the part lies above it.
  double travel = 0;
  for (const auto& axis : {machine.envelope.x, machine.envelope.y, machine.envelope.z})
    travel = std::max(travel, axis.travel.max - axis.travel.min);
  verifier.set_ceiling(2 * travel + 1000);
  gcode::Interpreter interpreter(machine, "verification");
  const config::Setup* current = nullptr;
  for (const config::Setup& s : machine.setups)
    if (s.work_offset == 54) current = &s;
  for (std::size_t k = 0; k < program.lines.size(); ++k) {
    const gcode::LineResult& done = interpreter.execute_line(program.lines[k], int(k + 1));
    const gcode::ProgramAction* action = program.action_at(std::uint32_t(k + 1));
    for (const gcode::Motion& m : done.motions) {
      if (m.work_offset != 53)
        for (const config::Setup& s : machine.setups)
          if (s.work_offset == m.work_offset) current = &s;
      if (!current) continue;
      if (m.is_arc() && m.plane != gcode::Plane::XY) continue;  // as the simulated machine: XY arcs only
      verifier.move(m, *current, action ? action->number : 0, options.arc_tolerance);
    }
  }
  verifier.sweep();
  return verifier.result(options.tolerance);
}

DesignSurfaces::DesignSurfaces(geometry::TriangleMesh mesh, std::string name)
    : mesh_(std::move(mesh)), name_(std::move(name)) {}

const DesignSurface* DesignSurfaces::for_plan(const plan::PlanFile& file) {
  const std::lock_guard<std::mutex> lock(mutex_);
  const double voxel = file.lattice.voxel_size;
  if (surface_ && tolerance_ == file.tolerance && voxel_ == voxel) return surface_.get();
  if (!mesh_) {
    // The STL the plan file read (plan::PlanFile::design_mesh); none: nothing to verify against.
    std::error_code ec;
    if (file.design_mesh.triangles.empty()) {
      if (file.part.empty()) return nullptr;
      throw InputError((file.directory / plan::kDesignStl).string() + ": not found, and neither is the part the plan names (" +
                       file.part + "): exact verification needs the design's STL; expected a plan directory as `plan -o` writes it");
    }
    const bool copy = !file.directory.empty() && std::filesystem::is_regular_file(file.directory / plan::kDesignStl, ec);
    name_ = copy ? (file.directory / plan::kDesignStl).string() : file.part;
    mesh_ = file.design_mesh;
  }
  surface_ = std::make_unique<DesignSurface>(*mesh_, name_, sampling_for(file.tolerance, voxel));
  tolerance_ = file.tolerance;
  voxel_ = voxel;
  return surface_.get();
}

}  // namespace hybridctl::verification
