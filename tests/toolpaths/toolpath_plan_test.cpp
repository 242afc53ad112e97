// Toolpaths for a real plan: the bundled flanged hub on the bundled hybrid machine, planned
// at a coarse 1 mm voxel so that the test stays quick. Every action of a hybrid plan
// (deposition from above and from below, milling) gets its toolpath; milling
// never puts the tool (cutter, shank, holder) where it would touch what the action keeps,
// checked at 1/8-voxel steps against the allowed region computed here from the planner's
// own instrument; deposition stays in its region.

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>

#include "config/machine_loader.hpp"
#include "toolpaths/deposition_path.hpp"
#include "toolpaths/pocket_path.hpp"
#include "toolpaths/setup_frame.hpp"
#include "geometry/morphology.hpp"
#include "geometry/mesh.hpp"
#include "planner/pipeline/planning.hpp"
#include "toolpath_oracles.hpp"

namespace hybridctl::toolpaths {
namespace {

using geometry::Solid;
using geometry::Vec3;

TEST(ToolpathsForAPlan, FlangedHubOnTheHybridMachine) {
  const config::Machine machine = config::load_machine(HYBRIDCTL_SOURCE_DIR "/examples/machines/hybrid-3axis.yaml");
  const geometry::TriangleMesh part = geometry::read_stl(HYBRIDCTL_SOURCE_DIR "/examples/parts/flanged-hub.stl");
  planner::PlanningOptions options;
  options.voxel_size = 0.5;
  options.top_k = 10;
  // Not validated by execution (the planner alone): the subject is each action's toolpath
  // against its region, not whether the plan makes the part. The first plan that mills and
  // deposits is plan 9: deposit the hub from -Z (turned over, the flange on the plate),
  // then mill it to size from -Z.
  const planner::PlanningResult r = planner::plan_part(part, "flanged-hub", machine, options);
  // The first plan that mills and deposits.
  const planner::Plan* plan = nullptr;
  for (const auto& p : r.plans) {
    bool mills = false, deposits = false;
    for (const auto& s : p.steps) {
      const auto& prim = r.primitives[std::size_t(s.primitive)];
      mills = mills || prim.mode == config::Mode::Subtractive;
      deposits = deposits || (prim.mode == config::Mode::Additive && prim.kind != config::PrimitiveKind::RawStock);
    }
    if (mills && deposits) {
      plan = &p;
      break;
    }
  }
  ASSERT_NE(plan, nullptr) << "no hybrid plan among the " << r.plans.size() << " best";

  const auto t0 = std::chrono::steady_clock::now();
  Solid state(r.lattice, r.domain);
  int milled = 0, deposited = 0;
  for (const auto& step : plan->steps) {
    const planner::Primitive& prim = r.primitives[std::size_t(step.primitive)];
    SCOPED_TRACE(prim.label);
    if (prim.kind == config::PrimitiveKind::RawStock) {
      state = geometry::unite(state, prim.region);
      continue;
    }
    const config::Setup& setup = *machine.find_setup(prim.setup);
    if (prim.mode == config::Mode::Additive) {
      const config::AdditiveHead& head = *machine.find_head(prim.capability);
      const Solid roi = geometry::subtract(prim.region, state);
      const Toolpath p = deposition_path(roi, state, head, setup);
      EXPECT_EQ(p.tool_number, head.tool_number);
      EXPECT_GE(p.tool_number, 100);
      const Solid roi_w = part_to_work(roi, setup.approach);
      const double h = r.lattice.voxel_size;
      int outside = 0, segments = 0;
      const auto starts = testing::move_starts(p);
      for (std::size_t i = 0; i < p.moves.size(); ++i) {
        if (!p.moves[i].process_on) continue;
        ++segments;
        // The voxel layers whose centres lie in the layer's band.
        const double zb = p.moves[i].to.z - r.lattice.origin.z;
        int k_lo = int(std::ceil(zb / h - 0.5 - 1e-9)), k_hi = int(std::ceil((zb + head.layer_height) / h - 0.5 - 1e-9)) - 1;
        if (k_hi < k_lo) k_lo = k_hi = int(std::floor((zb + head.layer_height / 2) / h));  // a band with no centre
        testing::along(starts[i], p.moves[i].to, h / 8, [&](Vec3 q) {
          bool near = false;
          for (int k = k_lo; k <= k_hi; ++k)
            for (double dx : {-h / 2, 0.0, h / 2})
              for (double dy : {-h / 2, 0.0, h / 2})
                near = near || roi_w.contains({int(std::floor((q.x + dx - r.lattice.origin.x) / h)),
                                               int(std::floor((q.y + dy - r.lattice.origin.y) / h)), k});
          outside += near ? 0 : 1;
        });
      }
      EXPECT_GT(segments, 10);
      EXPECT_EQ(outside, 0);
      ++deposited;
      state = geometry::unite(state, prim.region);
    } else {
      const config::CuttingTool& tool = *machine.find_tool(prim.tool_number);
      const Solid roi = geometry::intersect(prim.region, state);
      const Solid keep = geometry::subtract(state, prim.region);
      const Toolpath p = pocket_path(roi, keep, state, tool, setup);
      EXPECT_EQ(p.tool_number, tool.number);
      // The allowed tips, from the planner's instrument in the work frame.
      const Solid keep_w = part_to_work(keep, setup.approach);
      const auto instrument = planner::tool_instrument(tool, config::Approach::PlusZ);
      geometry::IndexBox domain = part_to_work(roi, setup.approach).bounding_box();
      domain = {{domain.lo.x - 20, domain.lo.y - 20, domain.lo.z - 1}, {domain.hi.x + 20, domain.hi.y + 20, domain.hi.z + 60}};
      Solid forbidden(r.lattice, domain);
      for (const auto* group : {&instrument.cutting, &instrument.body})
        for (const auto& e : *group)
          forbidden = geometry::unite(forbidden, geometry::dilate(keep_w, geometry::reflected(e), domain));
      const double h = r.lattice.voxel_size;
      int feeds = 0, outside = 0;
      const auto starts = testing::move_starts(p);
      for (std::size_t i = 0; i < p.moves.size(); ++i) {
        if (p.moves[i].kind == MoveKind::Rapid) continue;
        ++feeds;
        testing::along(starts[i], p.moves[i].to, h / 8, [&](Vec3 q) {
          // The voxel holding the tip, and the one below when the tip is under its centre:
          // the tool must clear both.
          const int x = int(std::floor((q.x - r.lattice.origin.x) / h)), y = int(std::floor((q.y - r.lattice.origin.y) / h));
          const double fz = (q.z - r.lattice.origin.z) / h - 0.5;
          for (int z : {int(std::floor(fz + 1e-9)), int(std::ceil(fz - 1e-9))})
            if (forbidden.contains({x, y, z}) && ++outside <= 5)
              ADD_FAILURE() << "move " << i << " tip at (" << q.x << ", " << q.y << ", " << q.z << ") is not allowed";
        });
      }
      EXPECT_GT(feeds, 10);
      EXPECT_EQ(outside, 0);
      ++milled;
      state = geometry::subtract(state, prim.region);
    }
  }
  EXPECT_GE(milled, 1);
  EXPECT_GE(deposited, 1);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("toolpaths for %zu actions in %.2f s\n", plan->steps.size(), seconds);
}

}  // namespace
}  // namespace hybridctl::toolpaths
