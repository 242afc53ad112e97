#pragma once
// Exact verification: the part a program makes, measured against the design's real
// surface, whatever the voxel (docs/verification.md).
//
// The point-vector method of NC verification: every sample of the design's surface
// (verification/design_surface.hpp) carries a vector along its normal, a short way into the
// design and out of it. Along each vector the material is kept as intervals: the start
// stock's (its voxels' cubes), then, move by move in program order, every cutter's swept
// volume (exact, verification/line_sweep.hpp) takes its interval away and every bead laid
// adds its own. What is left says, at that sample:
//  - excess: the farthest material beyond the surface, measured as its distance from the
//    design's surface (so a tool's radius left in an inside corner counts as the fillet
//    it is, not as its length along one face's normal);
//  - gouge: the deepest air under the surface, measured the same way.
// A surface last made by a bead lies within its head's as-deposited accuracy of the
// modelled bead, either way: both figures grow by it there. Each figure names the action
// and the line whose move left that surface. Between samples the error is bounded by the
// spacing and the surface's curvature (docs/verification.md).

#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "config/machine.hpp"
#include "gcode/program.hpp"
#include "geometry/solid.hpp"
#include "plan/deviation.hpp"
#include "plan/plan_file.hpp"
#include "verification/design_surface.hpp"

namespace hybridctl::verification {

struct VerifyOptions {
  double tolerance = 0;           // mm, the part's: what "within" means
  double arc_tolerance = 0.001;   // mm, the chords an arc is followed with
};

// Executes `program` (the whole plan's, as export writes it: setups by work offset,
// tools and heads by T number, machine coordinates) from `start_stock` (part frame; empty:
// nothing at the start) and measures the part it makes against `surface`. The program is
// one that ran without a refused line on the simulated machine; a line the interpreter
// refuses throws its GcodeError.
plan::ExactDeviation verify_program(const DesignSurface& surface, const config::Machine& machine,
                                    const gcode::PostedProgram& program, const geometry::Solid& start_stock,
                                    const VerifyOptions& options);

// What the part made is at one sample of the surface, as the summary counts it: how far
// its material stands out beyond the design's surface and how deep its air lies under it
// (0: none; an as-deposited face carries its head's accuracy both ways), and the action
// whose move left that surface (0: the start stock).
struct SampleDeviation {
  double excess = 0;  // mm
  double gouge = 0;   // mm
  int action = 0;
  bool as_deposited = false;
};

// The summary and every sample's figures, in the order of surface.samples(): for a
// report that paints the design's mesh, and for tests that compare sections.
struct SurfaceDeviation {
  plan::ExactDeviation summary;
  std::vector<SampleDeviation> samples;
};
SurfaceDeviation measure_program(const DesignSurface& surface, const config::Machine& machine,
                                 const gcode::PostedProgram& program, const geometry::Solid& start_stock,
                                 const VerifyOptions& options);

// The design's surface for a plan file, sampled once for its tolerance and voxel
// (sampling_for) and kept: from a mesh in memory (planning, which has read the STL), or from
// the STL the plan file names (export, run and dry-run of a plan directory).
class DesignSurfaces {
 public:
  DesignSurfaces() = default;
  DesignSurfaces(geometry::TriangleMesh mesh, std::string name);
  // From the mesh given, else the plan file's (plan::PlanFile::design_mesh). Null when
  // there is no real surface to verify against: no mesh, and the plan file names no part
  // (a design made on voxels, as tests make them). Throws InputError when it names a part
  // and neither its STL nor the directory's design.stl is there.
  const DesignSurface* for_plan(const plan::PlanFile& file);

 private:
  std::mutex mutex_;
  std::optional<geometry::TriangleMesh> mesh_;
  std::string name_;
  std::unique_ptr<DesignSurface> surface_;
  double tolerance_ = 0, voxel_ = 0;
};

}  // namespace hybridctl::verification
