// The flanged hub's exact deviation, checked by an exact cross-section test of its own.
//
// `plan` holds every plan it offers to the STL's real surface (docs/verification.md): it
// replays the whole program with the product's 3D sweeps and measures, at each sample of
// the surface, the material standing out of it (excess) and the air under it (gouge).
// This test measures the same samples of the bundled flanged hub by another road, which
// shares none of that code:
//  - the program is the file `plan --export` writes, interpreted by LinuxCNC's rs274
//    (scripts/rs274), not by ours: its canonical STRAIGHT_TRAVERSE, STRAIGHT_FEED and
//    ARC_FEED calls, each with the tool (SELECT_TOOL, CHANGE_TOOL), the work offset
//    (SET_G5X_OFFSET) and the action (the heading comment) it runs with;
//  - a flat end mill is a vertical cylinder in its setup's work frame, so its swept volume
//    cut by a horizontal plane is exactly the union of its disks along the stretch of the
//    move where its flutes span the plane: a capsule for a line, a round-ended ring sector
//    for an arc. Along a wall sample's horizontal normal each is met in closed form: the
//    ray's crossings of the shape's boundary circles and lines cut it into pieces that lie
//    wholly in or out, and each piece's middle is tested against the definition
//    (distance to the cutter's path within its radius). The flutes are what cuts: the
//    shank and holder must touch no material (validation's body_collision), and at the
//    heights measured here the program brings neither near the walls;
//  - the stock is the machine file's plate: the STL's bounding box grown by its margins;
//  - distances to the design are to the STL's triangles, one by one.
// At a few heights on the hub's wall and the flange's rim, every sample of the product's
// surface with a horizontal normal within a band of the height is measured both ways at
// its own height; the figures must agree within 0.01 mm (the "Done when"), each
// section's largest too, and the section of the STL at the height must pass through the
// samples with their normals.
//
// LinuxCNC's rs274 comes from scripts/setup (unpacked into .peers/linuxcnc, run by
// scripts/rs274, as tests/gcode/rs274_test.cpp and tests/cli/export_test.cpp run it).
// Missing, it is a failure with instructions, not a skip.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <iostream>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "../cli/shell.hpp"
#include "config/machine_loader.hpp"
#include "gcode/program.hpp"
#include "geometry/mesh.hpp"
#include "plan/deviation.hpp"
#include "plan/plan_file.hpp"
#include "plan/start_stock.hpp"
#include "independent_part.hpp"
#include "verification/exact_deviation.hpp"

namespace {

namespace fs = std::filesystem;
using hybridctl::geometry::Vec3;
using namespace hybridctl;
using namespace hybridctl::cli_testing;  // Outcome, quote, slurp, run_shell

const fs::path kSource = HYBRIDCTL_SOURCE_DIR;
const fs::path kPart = kSource / "examples/parts/flanged-hub.stl";
const fs::path kMachine = kSource / "examples/machines/hybrid-3axis.yaml";
constexpr double kAgree = 0.01;  // mm: the bar
using verification::independent::kPi;
namespace independent = verification::independent;

// ---------------------------------------------------------------------------------------
// The program as LinuxCNC's interpreter reads it.

// One move of a cutter, in the work frame of the setup it runs in. rs274 runs without
// offsets, so its canonical coordinates are the program's, which are the work frame's
// (docs/machine-file.md: program coordinates + work_origin = machine coordinates); it
// prints them to 4 decimals, and this program's are quarter millimetres. Its G53 retracts
// (machine Z 300) read as work Z 300: far above the part either way.
struct Cut : independent::CanonicalMove {
  config::Approach approach = config::Approach::PlusZ;  // of the setup it runs in
  double radius = 0, flute = 0;
};

struct Canonical {
  std::vector<Cut> cuts;
  int deposits = 0;       // SET_AUX_OUTPUT_BIT: a head's output on (M64)
  int other_planes = 0;   // arcs out of the XY plane
  int other_cutters = 0;  // moves of a cutting tool that is not a flat end mill
  int other_setups = 0;   // moves in a work offset of no setup, or of one not from +Z or -Z
};

// The moves of cutting tools, from rs274's canonical calls (independent_part.hpp).
Canonical read_cuts(const std::string& text, const config::Machine& machine) {
  const independent::CanonicalProgram program = independent::read_canonical(text);
  Canonical out;
  out.deposits = program.deposits;
  out.other_planes = program.other_planes;
  for (const independent::CanonicalMove& move : program.moves) {
    if (move.tool == 0) continue;
    const auto t = std::find_if(machine.tools.begin(), machine.tools.end(),
                                [&](const config::CuttingTool& c) { return c.number == move.tool; });
    const auto setup = std::find_if(machine.setups.begin(), machine.setups.end(),
                                    [&](const config::Setup& s) { return s.work_offset == move.work_offset; });
    if (t == machine.tools.end()) {
      // A head, which lays nothing unless its output is on (counted by the reader).
    } else if (t->type != config::ToolType::Flat) {
      ++out.other_cutters;
    } else if (setup == machine.setups.end() ||
               (setup->approach != config::Approach::PlusZ && setup->approach != config::Approach::MinusZ)) {
      ++out.other_setups;
    } else {
      Cut cut;
      static_cast<independent::CanonicalMove&>(cut) = move;
      cut.approach = setup->approach;
      cut.radius = t->diameter / 2, cut.flute = t->flute_length;
      out.cuts.push_back(cut);
    }
  }
  return out;
}

// ---------------------------------------------------------------------------------------
// Frames (docs/machine-file.md, "setups"): the work frame is the part frame turned so that
// the approach becomes +Z; from -Z that is half a turn about X. (The hub's setups are
// these two; read_canonical counts moves in any other.)

Vec3 to_work(const Vec3& p, config::Approach approach) {
  return approach == config::Approach::MinusZ ? Vec3{p.x, -p.y, -p.z} : p;
}

// ---------------------------------------------------------------------------------------
// 2D: what a horizontal ray meets of a cutter's section.

struct Ray {
  double ox = 0, oy = 0, ux = 0, uy = 0;  // o + s u, |u| = 1
  double x(double s) const { return ox + s * ux; }
  double y(double s) const { return oy + s * uy; }
};

// Where |o + s u - c| = rho.
void circle_crossings(const Ray& ray, double cx, double cy, double rho, std::vector<double>& out) {
  if (rho <= 0) return;
  const double dx = ray.ox - cx, dy = ray.oy - cy;
  const double b = dx * ray.ux + dy * ray.uy, c = dx * dx + dy * dy - rho * rho;
  const double disc = b * b - c;
  if (disc < 0) return;
  out.push_back(-b - std::sqrt(disc));
  out.push_back(-b + std::sqrt(disc));
}

double arc_distance(double px, double py, double cx, double cy, double r, double a0, double sweep) {
  const double ring = std::abs(std::hypot(px - cx, py - cy) - r);
  if (std::abs(sweep) >= 2 * kPi) return ring;
  const double phi = std::atan2(py - cy, px - cx);
  double rel = sweep > 0 ? phi - a0 : a0 - phi;
  rel = std::fmod(rel, 2 * kPi);
  if (rel < 0) rel += 2 * kPi;
  if (rel <= std::abs(sweep)) return ring;
  const double a1 = a0 + sweep;
  return std::min(std::hypot(px - cx - r * std::cos(a0), py - cy - r * std::sin(a0)),
                  std::hypot(px - cx - r * std::cos(a1), py - cy - r * std::sin(a1)));
}

using Interval = independent::Removal;
using Figures = independent::RayFigures;

// The parameter range [t0, t1] of a move (0..1 along it) over which a cutter whose tip
// is at z(t) spans height h with its flutes: z(t) <= h <= z(t) + flute.
std::optional<std::pair<double, double>> spanning(double z0, double z1, double h, double flute) {
  if (z0 == z1) {
    if (h < z0 || h > z0 + flute) return std::nullopt;
    return std::pair{0.0, 1.0};
  }
  double ta = (h - flute - z0) / (z1 - z0), tb = (h - z0) / (z1 - z0);
  if (ta > tb) std::swap(ta, tb);
  ta = std::max(ta, 0.0), tb = std::min(tb, 1.0);
  if (ta > tb) return std::nullopt;
  return std::pair{ta, tb};
}

// Where along `ray`, within [lo, hi], the cut's section at height h lies: the pieces
// between the crossings of its boundary, each tested at its middle.
void ray_in_cut(const Ray& ray, double lo, double hi, const Cut& cut, double h, std::vector<Interval>& out) {
  const auto span = spanning(cut.from.z, cut.to.z, h, cut.flute);
  if (!span) return;
  const double rad = cut.radius;
  std::vector<double> breaks{lo, hi};
  std::function<double(double, double)> distance;
  if (!cut.arc) {
    const double ax = cut.from.x + span->first * (cut.to.x - cut.from.x);
    const double ay = cut.from.y + span->first * (cut.to.y - cut.from.y);
    const double bx = cut.from.x + span->second * (cut.to.x - cut.from.x);
    const double by = cut.from.y + span->second * (cut.to.y - cut.from.y);
    // Far from the ray's reach: nothing to do.
    const double mx = 0.5 * (ray.x(lo) + ray.x(hi)), my = 0.5 * (ray.y(lo) + ray.y(hi));
    if (independent::segment_distance_2d(mx, my, ax, ay, bx, by) > rad + 0.5 * (hi - lo) + 1e-6) return;
    circle_crossings(ray, ax, ay, rad, breaks);
    circle_crossings(ray, bx, by, rad, breaks);
    const double len = std::hypot(bx - ax, by - ay);
    if (len > 0) {
      const double tx = (bx - ax) / len, ty = (by - ay) / len;
      const double across = tx * ray.uy - ty * ray.ux;  // d/ds of the signed distance from the path
      const double at0 = tx * (ray.oy - ay) - ty * (ray.ox - ax);
      if (std::abs(across) > 1e-15)
        for (double side : {-rad, rad}) breaks.push_back((side - at0) / across);
    }
    distance = [=](double x, double y) { return independent::segment_distance_2d(x, y, ax, ay, bx, by); };
  } else {
    const double a0 = cut.a0 + span->first * cut.sweep, sweep = (span->second - span->first) * cut.sweep;
    const double cx = cut.cx, cy = cut.cy, r = cut.r;
    const double mx = 0.5 * (ray.x(lo) + ray.x(hi)), my = 0.5 * (ray.y(lo) + ray.y(hi));
    if (arc_distance(mx, my, cx, cy, r, a0, sweep) > rad + 0.5 * (hi - lo) + 1e-6) return;
    circle_crossings(ray, cx, cy, r + rad, breaks);
    circle_crossings(ray, cx, cy, r - rad, breaks);
    for (double a : {a0, a0 + sweep})
      circle_crossings(ray, cx + r * std::cos(a), cy + r * std::sin(a), rad, breaks);
    distance = [=](double x, double y) { return arc_distance(x, y, cx, cy, r, a0, sweep); };
  }
  std::sort(breaks.begin(), breaks.end());
  for (std::size_t i = 0; i + 1 < breaks.size(); ++i) {
    const double a = std::max(breaks[i], lo), b = std::min(breaks[i + 1], hi);
    if (!(b > a)) continue;
    const double m = 0.5 * (a + b);
    if (distance(ray.x(m), ray.y(m)) > rad) continue;
    if (!out.empty() && out.back().action == cut.action && std::abs(out.back().hi - a) < 1e-12) out.back().hi = b;
    else out.push_back({a, b, cut.action});
  }
}

// ---------------------------------------------------------------------------------------
// The independent figures at one wall sample.

struct Model {
  const geometry::TriangleMesh* mesh = nullptr;
  std::vector<Cut> cuts;
  Vec3 stock_lo, stock_hi;  // the plate, part frame
};

// Material along the sample's vector: the stock's, less every cutter's sweep (the plan lays
// no bead, so the order of the cuts does not matter); then excess and gouge as
// docs/verification.md defines them.
Figures measure(const Model& model, Vec3 p, Vec3 n, double inward, double outward) {
  const double lo = -inward, hi = outward;
  // The stock: the ray's stretch inside the box (n is horizontal).
  double s0 = lo, s1 = p.z < model.stock_lo.z || p.z > model.stock_hi.z ? lo - 1 : hi;
  const double pp[2] = {p.x, p.y}, nn[2] = {n.x, n.y};
  const double blo[2] = {model.stock_lo.x, model.stock_lo.y}, bhi[2] = {model.stock_hi.x, model.stock_hi.y};
  for (int a = 0; a < 2; ++a) {
    if (std::abs(nn[a]) < 1e-15) {
      if (pp[a] < blo[a] || pp[a] > bhi[a]) s1 = s0 - 1;
      continue;
    }
    double t0 = (blo[a] - pp[a]) / nn[a], t1 = (bhi[a] - pp[a]) / nn[a];
    if (t0 > t1) std::swap(t0, t1);
    s0 = std::max(s0, t0), s1 = std::min(s1, t1);
  }
  std::vector<Interval> removed;
  for (const Cut& cut : model.cuts) {
    const Vec3 wp = to_work(p, cut.approach), wn = to_work(n, cut.approach);
    ray_in_cut(Ray{wp.x, wp.y, wn.x, wn.y}, lo, hi, cut, wp.z, removed);
  }
  return independent::ray_figures(*model.mesh, p, n, inward, s0, s1, std::move(removed));
}

// The arcs' sweep above is not needed by this plan's program (lines only), so it is checked
// here against what it must equal: the union of the capsules of the arc's fine chords,
// along rays across it, for a quarter turn each way and a helix through the height.
TEST(HubSectionsModel, AnArcsSectionIsTheUnionOfItsChordsSections) {
  const auto merged = [](std::vector<Interval> v) {
    std::sort(v.begin(), v.end(), [](const Interval& a, const Interval& b) { return a.lo < b.lo; });
    std::vector<Interval> out;
    for (const Interval& i : v)
      if (!out.empty() && i.lo <= out.back().hi + 1e-9) out.back().hi = std::max(out.back().hi, i.hi);
      else out.push_back(i);
    return out;
  };
  std::size_t met = 0;
  for (const double sweep : {kPi / 2, -kPi / 2, 1.5 * kPi}) {
    Cut arc;
    arc.arc = true, arc.radius = 5, arc.flute = 22;
    arc.cx = 10, arc.cy = 20, arc.r = 12, arc.a0 = 0.3, arc.sweep = sweep;
    arc.from = {0, 0, -4}, arc.to = {0, 0, 4};  // the flutes leave height 0 part of the way
    std::vector<Cut> chords;
    const int n = 4000;
    for (int k = 0; k < n; ++k) {
      Cut c = arc;
      c.arc = false;
      const double t0 = double(k) / n, t1 = double(k + 1) / n;
      const double b0 = arc.a0 + t0 * sweep, b1 = arc.a0 + t1 * sweep;
      c.from = {arc.cx + arc.r * std::cos(b0), arc.cy + arc.r * std::sin(b0), -4 + 8 * t0};
      c.to = {arc.cx + arc.r * std::cos(b1), arc.cy + arc.r * std::sin(b1), -4 + 8 * t1};
      chords.push_back(c);
    }
    for (const double angle : {0.0, 0.7, 1.9, 3.3, 4.4}) {
      const Ray ray{10 + 3 * std::cos(angle + 1), 20 + 3 * std::sin(angle + 1), std::cos(angle), std::sin(angle)};
      std::vector<Interval> exact, approximated;
      ray_in_cut(ray, -40, 40, arc, 0, exact);
      for (const Cut& c : chords) ray_in_cut(ray, -40, 40, c, 0, approximated);
      const std::vector<Interval> a = merged(exact), b = merged(approximated);
      ASSERT_EQ(a.size(), b.size()) << "sweep " << sweep << ", ray at " << angle;
      met += a.size();
      for (std::size_t i = 0; i < a.size(); ++i) {
        EXPECT_NEAR(a[i].lo, b[i].lo, 1e-3) << "sweep " << sweep << ", ray at " << angle;
        EXPECT_NEAR(a[i].hi, b[i].hi, 1e-3) << "sweep " << sweep << ", ray at " << angle;
      }
    }
  }
  EXPECT_GE(met, 10u) << "most rays cross the arc's section";
}

// ---------------------------------------------------------------------------------------

// One plan of the hub, exported, read by LinuxCNC and by the product, for every test here.
struct Hub {
  fs::path dir;
  config::Machine machine;
  geometry::TriangleMesh mesh;
  plan::PlanFile file;
  nlohmann::json reported;  // plan.json's deviation.exact of the plan
  std::unique_ptr<verification::DesignSurfaces> surfaces;
  const verification::DesignSurface* surface = nullptr;
  verification::SurfaceDeviation product;
  Model model;
  std::string failure;  // why the hub could not be set up
};

class HubSections : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    hub_ = new Hub;
    Hub& h = *hub_;
    h.dir = independent::fresh_directory("hybridctl-hub-sections");
    if (const std::string missing = independent::rs274_missing(kSource); !missing.empty()) {
      h.failure = missing;
      return;
    }
    // The machine file's own settings (tolerance 0.5 mm, voxel 0.5 mm): the plan `plan`
    // offers first for the bundled hub.
    const Outcome planned = run_shell(quote(HYBRIDCTL_EXE) + " plan " + quote(kPart.string()) + " --machine " +
                                          quote(kMachine.string()) + " --top 1 -o " + quote((h.dir / "plan").string()) +
                                          " --export " + quote((h.dir / "out").string()),
                                      h.dir);
    if (planned.exit_code != 0) {
      h.failure = "hybridctl plan failed:\n" + planned.out + planned.err;
      return;
    }
    const Outcome canonical =
        run_shell(independent::rs274_command(kSource, h.dir / "out/tool.tbl", h.dir / "out/plan-1.ngc"), h.dir);
    if (canonical.exit_code != 0) {
      h.failure = "rs274 refused plan-1.ngc:\n" + canonical.err.substr(0, 2000);
      return;
    }
    h.machine = config::load_machine(kMachine);
    h.mesh = geometry::read_stl(kPart);

    // The product's figures, as `plan` and `export` make them: the design's surface sampled
    // for the plan's tolerance and voxel, the plan's start stock, the exported program.
    h.file = plan::read_plan_file(h.dir / "plan");
    h.reported = nlohmann::json::parse(slurp(h.dir / "plan/plan.json"))["plans"][0]["deviation"]["exact"];
    h.surfaces = std::make_unique<verification::DesignSurfaces>();
    h.surface = h.surfaces->for_plan(h.file);
    const gcode::PostedProgram program = gcode::PostedProgram::from_text(slurp(h.dir / "out/plan-1.ngc"));
    h.product = verification::measure_program(*h.surface, h.machine, program,
                                              plan::start_stock(h.file, h.file.plans.at(0), h.machine),
                                              {h.file.tolerance});

    // The independent side.
    const Canonical c = read_cuts(canonical.out, h.machine);
    if (c.deposits > 0 || c.other_planes > 0 || c.other_cutters > 0 || c.other_setups > 0) {
      h.failure = "the plan's program is not what this test models (flat end mills from +Z or -Z, XY arcs, no bead): " +
                  std::to_string(c.deposits) + " deposits, " + std::to_string(c.other_planes) + " arcs out of XY, " +
                  std::to_string(c.other_cutters) + " moves of another cutter, " + std::to_string(c.other_setups) +
                  " in another setup";
      return;
    }
    h.model.mesh = &h.mesh;
    h.model.cuts = c.cuts;
    Vec3 lo{1e9, 1e9, 1e9}, hi{-1e9, -1e9, -1e9};
    for (const geometry::Triangle& t : h.mesh.triangles)
      for (const Vec3& v : t) {
        lo = {std::min(lo.x, v.x), std::min(lo.y, v.y), std::min(lo.z, v.z)};
        hi = {std::max(hi.x, v.x), std::max(hi.y, v.y), std::max(hi.z, v.z)};
      }
    // The raw stock the plan starts from: a box round the part (the plate, margins 2, 2, 3).
    const plan::PlanFilePrimitive& first = h.file.primitives.at(h.file.plans.at(0).actions.at(0).primitive);
    const auto stock = std::find_if(h.machine.raw_stocks.begin(), h.machine.raw_stocks.end(),
                                    [&](const config::RawStock& s) { return s.name == first.capability; });
    if (!first.raw_stock() || stock == h.machine.raw_stocks.end() || stock->kind != config::RawStock::Kind::Box) {
      h.failure = "the plan does not start from a box of raw stock: " + first.label;
      return;
    }
    const auto& m = stock->margin;
    h.model.stock_lo = {lo.x - m[0], lo.y - m[1], lo.z - m[2]};
    h.model.stock_hi = {hi.x + m[0], hi.y + m[1], hi.z + m[2]};
  }
  static void TearDownTestSuite() {
    if (hub_) fs::remove_all(hub_->dir);
    delete hub_;
    hub_ = nullptr;
  }
  void SetUp() override { ASSERT_TRUE(hub_->failure.empty()) << hub_->failure; }

  static Hub* hub_;
};
Hub* HubSections::hub_ = nullptr;

// The plan this test reads is the one it expects: the plate milled from below (the hub's
// wall, the flange's underside and rim) and then from above (the top face), and what `plan`
// reported for it is what measure_program measures on the exported program.
TEST_F(HubSections, ThePlansReportedExactDeviationIsTheExportedProgramsMeasure) {
  const Hub& h = *hub_;
  ASSERT_EQ(h.file.plans.size(), 1u);
  std::vector<std::string> steps;
  for (const plan::PlanFileAction& a : h.file.plans[0].actions)
    steps.push_back(h.file.primitives.at(a.primitive).label);
  ASSERT_EQ(steps.size(), 3u);
  EXPECT_EQ(steps[0], "raw stock plate (box)");
  EXPECT_EQ(steps[1], "SM-max T1 (10 mm flat rougher) from -Z (bottom)");
  EXPECT_EQ(steps[2], "SM-max T1 (10 mm flat rougher) from +Z (top)");
  EXPECT_NEAR(h.product.summary.excess.mm, h.reported["max_excess_mm"].get<double>(), 1e-9);
  EXPECT_NEAR(h.product.summary.gouge.mm, h.reported["max_gouge_mm"].get<double>(), 1e-9);
  EXPECT_EQ(h.product.samples.size(), h.surface->samples().size());
  EXPECT_GT(h.model.cuts.size(), 3000u) << "every move of T1, from LinuxCNC's reading";
  std::cout << "[ figures  ] plan 1 as `plan` reports it: " << plan::exact_deviation_text(h.product.summary) << "\n";
}

struct Height {
  double z;
  const char* where;
  double radius;  // the wall's, about the hub's axis (25, 25)
};

// Two heights on the hub's wall (one in the middle, one just under the flange) and one on
// the flange's rim. Each band stays clear of this plan's level tips and flute ends (from
// below, tips at part z 0, 1.75, 6.75 .. 26.75, 30, 31.75, 36.75, 38, and the wall
// finishing's also at 35, the flange's face; flutes 22 mm long; from above, a tip at 35),
// not that the figures need it: a cutter's reach is met exactly at any height.
constexpr Height kHeights[] = {{12.5, "hub wall", 10.0}, {28.0, "hub wall", 10.0}, {33.0, "flange rim", 25.0}};
constexpr double kBand = 0.5;  // mm either side: the product's samples measured for a height

std::string where(const Vec3& p) {
  std::ostringstream s;
  s << "(" << p.x << ", " << p.y << ", " << p.z << ")";
  return s.str();
}

// The wall samples of the product's surface within a height's band, and their figures both
// ways: the product's and the sections'.
struct SampleFigures {
  std::size_t index;
  verification::SampleDeviation product;
  Figures sections;
};

std::vector<SampleFigures> wall_samples(const Hub& h, const Height& height) {
  std::vector<SampleFigures> out;
  const auto& samples = h.surface->samples();
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const verification::SurfaceSample& s = samples[i];
    if (std::abs(s.normal.z) > 1e-9 || std::abs(s.point.z - height.z) > kBand) continue;
    if (std::abs(std::hypot(s.point.x - 25, s.point.y - 25) - height.radius) > 0.1) continue;
    out.push_back({i, h.product.samples[i], measure(h.model, s.point, s.normal, s.inward, s.outward)});
  }
  return out;
}

TEST_F(HubSections, EveryWallSampleAtTheSectionsHasTheExcessAndGougeTheCuttersSweptSectionsLeave) {
  const Hub& h = *hub_;
  const verification::SamplingOptions& sampling = h.surface->options();
  double largest = 0;
  for (const Height& height : kHeights) {
    SCOPED_TRACE(std::string(height.where) + " at z " + std::to_string(height.z));
    const std::vector<SampleFigures> figures = wall_samples(h, height);
    EXPECT_GE(figures.size(), 500u) << "the band holds the wall's samples all round";
    double worst = 0;
    Vec3 worst_at;
    for (const SampleFigures& f : figures) {
      const verification::SurfaceSample& s = h.surface->samples()[f.index];
      SCOPED_TRACE("sample " + std::to_string(f.index) + " at " + where(s.point));
      // The sample lies on the STL's section at its own height, its normal across the
      // wall, outward; its vector reaches as far as the sampling says (the design has
      // nothing else near it).
      double on = 1e9;
      for (const independent::SectionEdge& e : independent::mesh_section(h.mesh, 2, s.point.z))
        on = std::min(on, independent::segment_distance_2d(s.point.x, s.point.y, e.a0, e.b0, e.a1, e.b1));
      EXPECT_LT(on, 1e-6);
      EXPECT_GT((s.point.x - 25) * s.normal.x + (s.point.y - 25) * s.normal.y, 0);
      EXPECT_DOUBLE_EQ(s.inward, sampling.reach);
      EXPECT_DOUBLE_EQ(s.outward, sampling.reach);

      EXPECT_NEAR(f.product.excess, f.sections.excess, kAgree);
      EXPECT_NEAR(f.product.gouge, f.sections.gouge, kAgree);
      // The surface there is the last cut's that reached it, never a bead.
      EXPECT_TRUE(f.sections.surface_actions.count(f.product.action))
          << "the product names action " << f.product.action;
      EXPECT_FALSE(f.product.as_deposited);
      const double diff =
          std::max(std::abs(f.product.excess - f.sections.excess), std::abs(f.product.gouge - f.sections.gouge));
      if (diff > worst) worst = diff, worst_at = s.point;
    }
    std::cout << "[ figures  ] " << height.where << " z " << height.z << " +/- " << kBand << ": " << figures.size()
              << " samples, largest difference " << worst << " mm at " << where(worst_at) << "\n";
    largest = std::max(largest, worst);
  }
  std::cout << "[ figures  ] largest difference at any sample: " << largest << " mm\n";
}

// What the issue asks: the figures exact verification reports agree with the exact
// sections. At each height the STL's own section is walked every 0.05 mm, whatever the
// samples, and measured along its normal; its largest excess and gouge must be the
// largest the product reports for its samples in the band, within 0.01 mm (so the samples
// lie close enough on these walls for what falls between them not to matter). The walls
// are finished on the STL (docs/toolpaths.md, "Wall finishing"): the sections must find
// them standing off it by the finishing's clearance and chord tolerance, no more, and the
// product the same within a tenth of that bar (so that nothing passes for want of
// anything to measure: the clearance is there all round).
TEST_F(HubSections, EachSectionsLargestExcessAndGougeAreTheOnesTheProductReportsThere) {
  const Hub& h = *hub_;
  const double reach = h.surface->options().reach;
  for (const Height& height : kHeights) {
    SCOPED_TRACE(std::string(height.where) + " at z " + std::to_string(height.z));
    const std::vector<independent::SectionEdge> section = independent::mesh_section(h.mesh, 2, height.z);
    ASSERT_FALSE(section.empty());
    // The wall is a 48-gon round (25, 25): its section lies between the apothem and the
    // radius (the STL's vertices are single precision), and its outside is away from the axis.
    const double apothem = height.radius * std::cos(kPi / 48);
    double section_excess = 0, section_gouge = 0;
    Vec3 excess_at, gouge_at;
    for (const independent::SectionEdge& edge : section) {
      const struct { double ax, ay, bx, by; } e{edge.a0, edge.b0, edge.a1, edge.b1};
      for (const double r : {std::hypot(e.ax - 25, e.ay - 25), std::hypot(e.bx - 25, e.by - 25)}) {
        EXPECT_GE(r, apothem - 1e-4);
        EXPECT_LE(r, height.radius + 1e-4);
      }
      const double len = std::hypot(e.bx - e.ax, e.by - e.ay);
      Vec3 n{(e.by - e.ay) / len, -(e.bx - e.ax) / len, 0};
      if ((0.5 * (e.ax + e.bx) - 25) * n.x + (0.5 * (e.ay + e.by) - 25) * n.y < 0) n = {-n.x, -n.y, 0};
      for (double t = 0; t <= len; t += 0.05) {
        const Vec3 p{e.ax + t / len * (e.bx - e.ax), e.ay + t / len * (e.by - e.ay), height.z};
        const Figures f = measure(h.model, p, n, reach, reach);
        if (f.excess > section_excess) section_excess = f.excess, excess_at = p;
        if (f.gouge > section_gouge) section_gouge = f.gouge, gouge_at = p;
      }
    }
    double product_excess = 0, product_gouge = 0, sampled_excess = 0, sampled_gouge = 0;
    for (const SampleFigures& f : wall_samples(h, height)) {
      product_excess = std::max(product_excess, f.product.excess);
      product_gouge = std::max(product_gouge, f.product.gouge);
      sampled_excess = std::max(sampled_excess, f.sections.excess);
      sampled_gouge = std::max(sampled_gouge, f.sections.gouge);
    }
    std::cout << "[ figures  ] " << height.where << " z " << height.z << ": excess " << section_excess << " at "
              << where(excess_at) << " (section), " << sampled_excess << " (section at the product's samples), "
              << product_excess << " (product); gouge " << section_gouge << " at " << where(gouge_at) << " (section), "
              << sampled_gouge << " (section at the product's samples), " << product_gouge << " (product)\n";
    EXPECT_NEAR(product_excess, section_excess, kAgree);
    EXPECT_NEAR(product_gouge, section_gouge, kAgree);
    EXPECT_NEAR(product_excess, sampled_excess, kAgree);
    EXPECT_NEAR(product_gouge, sampled_gouge, kAgree);
    // The flat rougher's side follows the STL's wall at 0.0002 to 0.0012 mm (clearance and
    // chord tolerance) plus the G-code's 0.0001 mm rounding, and where export fitted an arc
    // to the pass up to 0.001 mm more (the arc fitter's chord tolerance: an arc stands out
    // of the chords it replaces by up to that, away from its centre, and never passes inside
    // them: docs/toolpaths.md, "Arc fitting"): by LinuxCNC's reading and these sections,
    // the part stands off by no more than that and is nowhere inside. (Milled on the voxels
    // alone, the walls followed their staircases, 0.25-0.35 mm out and up to 0.12 mm in.)
    EXPECT_GT(section_excess, 0.0001);
    EXPECT_LT(section_excess, 0.0013 + 0.001);
    EXPECT_LT(section_gouge, 1e-6);
    EXPECT_NEAR(product_excess, section_excess, kAgree / 10);
  }
}

}  // namespace
