// A cylinder, a filleted corner and a sloped face finished at --tolerance 0.05, measured on
// exact cross-sections by a road that shares none of the product's code.
//
// The part is examples/parts/filleted-ramp-block.stl: a round boss (a wall the flat cutters
// finish on its sections), a concave fillet of radius 5 along X and a ramp 20 degrees from
// the horizontal (3D faces the ball finishes by drop-cutter). `plan` offers its plans at
// the tolerance a drawing would give these faces, 0.05 mm, and exports them; each plan's
// program is then
//  - interpreted by LinuxCNC's rs274 (scripts/rs274), not by ours: its canonical moves,
//    each with the tool, the work offset and the action it runs with (independent_part.hpp);
//  - swept with the cutter's real shape: a flat, ball or bull end mill is a convex body of
//    revolution (a cylinder of radius R - r whose height runs from r to the flute length
//    less r, grown by the corner radius r), so its sweep along a straight move is convex
//    too. A point is cut when its distance to the swept inner cylinder is at most r; along
//    a line that distance is convex in the move's parameter, and along a sample's vector
//    the cut stretch is one interval, found by a golden-section search and bisection to
//    1e-7 mm. Arcs are followed by chords 0.0001 mm inside them at most;
//  - applied to the raw stock the plan starts from (the machine file's box round the part).
// The STL is cut by planes across each face (horizontal through the boss, x = const
// through the fillet, y = const through the ramp) and each section is walked every 0.2 mm
// along the triangle's normal. The bar: every point within 0.05 mm of the STL both
// ways, and `plan`'s own exact deviation (plan.json) no smaller than what the sections find.
//
// LinuxCNC's rs274 comes from scripts/setup; missing, it is a failure with instructions.

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "../cli/shell.hpp"
#include "config/machine_loader.hpp"
#include "geometry/mesh.hpp"
#include "independent_part.hpp"
#include "plan/plan_file.hpp"

namespace {

namespace fs = std::filesystem;
using namespace hybridctl;
using namespace hybridctl::cli_testing;  // Outcome, quote, slurp, run_shell
namespace independent = verification::independent;
using geometry::Vec3;

const fs::path kSource = HYBRIDCTL_SOURCE_DIR;
const fs::path kPart = kSource / "examples/parts/filleted-ramp-block.stl";
const fs::path kMachine = kSource / "examples/machines/hybrid-3axis.yaml";
constexpr double kTolerance = 0.05;  // mm: the issue's
constexpr double kReach = 1.0;       // mm each way along a sample's normal
constexpr double kStep = 0.2;        // mm between samples along a section

// ---------------------------------------------------------------------------------------
// Frames (docs/machine-file.md, "setups"): the work frame is the part frame turned so that
// the approach becomes +Z, about the origin.

Vec3 to_work(const Vec3& p, config::Approach approach) {
  switch (approach) {
    case config::Approach::PlusZ: return p;
    case config::Approach::MinusZ: return {p.x, -p.y, -p.z};
    case config::Approach::PlusX: return {-p.z, p.y, p.x};
    case config::Approach::MinusX: return {p.z, p.y, -p.x};
    case config::Approach::PlusY: return {p.x, -p.z, p.y};
    case config::Approach::MinusY: return {p.x, p.z, -p.y};
  }
  return p;
}

// ---------------------------------------------------------------------------------------
// A cutter swept along a straight move, in its work frame (tool axis +Z, tip at `from` to
// `to`).

struct Sweep {
  config::Approach approach = config::Approach::PlusZ;
  int action = 0;
  double radius = 0, corner = 0, flute = 0;
  Vec3 from, to;
  Vec3 lo, hi;  // its box, work frame
};

// Distance from q (relative to the tip) to the cutter's inner cylinder: radius R - r,
// height r to max(r, flute - r).
double inner_distance(const Sweep& s, double qx, double qy, double qz) {
  const double d_rho = std::max(0.0, std::hypot(qx, qy) - (s.radius - s.corner));
  const double top = std::max(s.corner, s.flute - s.corner);
  const double d_z = std::max({0.0, s.corner - qz, qz - top});
  return std::hypot(d_rho, d_z);
}

// Golden-section search for the minimum of a convex function on [a, b].
template <class F>
double convex_minimum(F f, double a, double b, double tolerance, double* where = nullptr) {
  constexpr double g = 0.6180339887498949;
  double c = b - g * (b - a), d = a + g * (b - a);
  double fc = f(c), fd = f(d);
  while (b - a > tolerance) {
    if (fc < fd) b = d, d = c, fd = fc, c = b - g * (b - a), fc = f(c);
    else a = c, c = d, fc = fd, d = a + g * (b - a), fd = f(d);
  }
  const double m = 0.5 * (a + b);
  if (where) *where = m;
  return f(m);
}

// How far q (work frame) is outside the sweep: < = 0 inside.
double outside(const Sweep& s, const Vec3& q) {
  const auto at = [&](double t) {
    return inner_distance(s, q.x - s.from.x - t * (s.to.x - s.from.x), q.y - s.from.y - t * (s.to.y - s.from.y),
                          q.z - s.from.z - t * (s.to.z - s.from.z));
  };
  // To 0.00001 mm along the move: the distance at the minimum is off by about its square.
  const double length = std::sqrt((s.to.x - s.from.x) * (s.to.x - s.from.x) + (s.to.y - s.from.y) * (s.to.y - s.from.y) +
                                  (s.to.z - s.from.z) * (s.to.z - s.from.z));
  return convex_minimum(at, 0.0, 1.0, std::min(0.01, 1e-5 / std::max(length, 1e-9))) - s.corner;
}

// The stretch of p + s n, s in [lo, hi], that the sweep cuts (the work frame's p and n).
std::optional<std::pair<double, double>> cut_stretch(const Sweep& s, Vec3 p, Vec3 n, double lo, double hi) {
  const auto g = [&](double u) { return outside(s, {p.x + u * n.x, p.y + u * n.y, p.z + u * n.z}); };
  double best = 0;
  if (convex_minimum(g, lo, hi, 1e-6, &best) > 0) return std::nullopt;
  const auto edge = [&](double in, double out) {  // g(in) <= 0 < g(out)
    for (int k = 0; k < 60 && std::abs(out - in) > 1e-7; ++k) {
      const double m = 0.5 * (in + out);
      (g(m) <= 0 ? in : out) = m;
    }
    return in;
  };
  return std::pair{g(lo) <= 0 ? lo : edge(best, lo), g(hi) <= 0 ? hi : edge(best, hi)};
}

// ---------------------------------------------------------------------------------------
// The program as rs274 reads it, as sweeps.

struct Made {
  std::vector<Sweep> sweeps;
  Vec3 stock_lo, stock_hi;  // the raw box, part frame
  std::string unmodelled;   // what in the program this test does not model
};

void add_sweep(Made& made, Sweep s) {
  s.lo = {std::min(s.from.x, s.to.x) - s.radius, std::min(s.from.y, s.to.y) - s.radius, std::min(s.from.z, s.to.z)};
  s.hi = {std::max(s.from.x, s.to.x) + s.radius, std::max(s.from.y, s.to.y) + s.radius,
          std::max(s.from.z, s.to.z) + std::max(s.flute, 2 * s.corner)};
  made.sweeps.push_back(s);
}

Made sweeps_of(const std::string& canonical, const config::Machine& machine) {
  Made made;
  const independent::CanonicalProgram program = independent::read_canonical(canonical);
  if (program.deposits > 0) made.unmodelled += std::to_string(program.deposits) + " deposits; ";
  if (program.other_planes > 0) made.unmodelled += std::to_string(program.other_planes) + " arcs out of XY; ";
  for (const independent::CanonicalMove& move : program.moves) {
    const auto tool = std::find_if(machine.tools.begin(), machine.tools.end(),
                                   [&](const config::CuttingTool& t) { return t.number == move.tool; });
    if (tool == machine.tools.end()) continue;  // no cutter in the spindle (a head lays nothing: no deposits)
    const auto setup = std::find_if(machine.setups.begin(), machine.setups.end(),
                                    [&](const config::Setup& s) { return s.work_offset == move.work_offset; });
    if (setup == machine.setups.end()) {
      made.unmodelled += "a move in G" + std::to_string(move.work_offset) + ", no setup's; ";
      continue;
    }
    Sweep s;
    s.approach = setup->approach, s.action = move.action;
    s.radius = tool->diameter / 2, s.flute = tool->flute_length;
    s.corner = tool->type == config::ToolType::Flat ? 0.0
               : tool->type == config::ToolType::Ball ? tool->diameter / 2
                                                      : tool->corner_radius;
    if (!move.arc) {
      s.from = move.from, s.to = move.to;
      add_sweep(made, s);
      continue;
    }
    // Chords whose sagitta is at most 0.0001 mm: r (1 - cos(step / 2)) <= 1e-4.
    const double step = move.r > 0 ? 2 * std::acos(std::max(-1.0, 1 - 1e-4 / move.r)) : independent::kPi;
    const int n = std::max(1, int(std::ceil(std::abs(move.sweep) / step)));
    for (int k = 0; k < n; ++k) {
      const double t0 = double(k) / n, t1 = double(k + 1) / n;
      const double b0 = move.a0 + t0 * move.sweep, b1 = move.a0 + t1 * move.sweep;
      s.from = {move.cx + move.r * std::cos(b0), move.cy + move.r * std::sin(b0),
                move.from.z + t0 * (move.to.z - move.from.z)};
      s.to = {move.cx + move.r * std::cos(b1), move.cy + move.r * std::sin(b1),
              move.from.z + t1 * (move.to.z - move.from.z)};
      add_sweep(made, s);
    }
  }
  return made;
}

// The least distance between two segments in the plane.
double segments_distance_2d(double ax, double ay, double bx, double by, double cx, double cy, double dx, double dy) {
  const auto cross = [](double ux, double uy, double vx, double vy) { return ux * vy - uy * vx; };
  const double d1 = cross(bx - ax, by - ay, cx - ax, cy - ay), d2 = cross(bx - ax, by - ay, dx - ax, dy - ay);
  const double d3 = cross(dx - cx, dy - cy, ax - cx, ay - cy), d4 = cross(dx - cx, dy - cy, bx - cx, by - cy);
  if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0))) return 0;
  using independent::segment_distance_2d;
  return std::min({segment_distance_2d(ax, ay, cx, cy, dx, dy), segment_distance_2d(bx, by, cx, cy, dx, dy),
                   segment_distance_2d(cx, cy, ax, ay, bx, by), segment_distance_2d(dx, dy, ax, ay, bx, by)});
}

// The part made along a sample's vector (part frame p, unit n outward).
independent::RayFigures measure(const Made& made, const geometry::TriangleMesh& mesh, Vec3 p, Vec3 n) {
  const double lo = -kReach, hi = kReach;
  // The stock: the vector's stretch inside the box.
  double s0 = lo, s1 = hi;
  const double pp[3] = {p.x, p.y, p.z}, nn[3] = {n.x, n.y, n.z};
  const double blo[3] = {made.stock_lo.x, made.stock_lo.y, made.stock_lo.z};
  const double bhi[3] = {made.stock_hi.x, made.stock_hi.y, made.stock_hi.z};
  for (int a = 0; a < 3; ++a) {
    if (std::abs(nn[a]) < 1e-15) {
      if (pp[a] < blo[a] || pp[a] > bhi[a]) s1 = s0 - 1;
      continue;
    }
    double t0 = (blo[a] - pp[a]) / nn[a], t1 = (bhi[a] - pp[a]) / nn[a];
    if (t0 > t1) std::swap(t0, t1);
    s0 = std::max(s0, t0), s1 = std::min(s1, t1);
  }
  std::vector<independent::Removal> removed;
  for (const Sweep& s : made.sweeps) {
    const Vec3 wp = to_work(p, s.approach), wn = to_work(n, s.approach);
    const Vec3 a{wp.x + lo * wn.x, wp.y + lo * wn.y, wp.z + lo * wn.z}, b{wp.x + hi * wn.x, wp.y + hi * wn.y, wp.z + hi * wn.z};
    if (std::max(a.x, b.x) < s.lo.x || std::min(a.x, b.x) > s.hi.x || std::max(a.y, b.y) < s.lo.y ||
        std::min(a.y, b.y) > s.hi.y || std::max(a.z, b.z) < s.lo.z || std::min(a.z, b.z) > s.hi.z)
      continue;
    // The cutter is no wider than its radius about its axis: farther from the path in XY,
    // nothing of the vector is cut.
    if (segments_distance_2d(a.x, a.y, b.x, b.y, s.from.x, s.from.y, s.to.x, s.to.y) > s.radius + 1e-9) continue;
    if (const auto cut = cut_stretch(s, wp, wn, lo, hi)) removed.push_back({cut->first, cut->second, s.action});
  }
  return independent::ray_figures(mesh, p, n, kReach, s0, s1, std::move(removed));
}

// ---------------------------------------------------------------------------------------
// The model against its definition: a point is cut when the cutter, at some position along
// the move, holds it. Each cutter shape, on lines that climb, fall and run level, at random
// points near them; positions every 1/20000 of the move (points closer than 0.002 mm to the
// boundary by either measure are not judged).

TEST(FinishedFacesSectionsModel, ASweepHoldsExactlyThePointsACutterPositionAlongTheMoveHolds) {
  std::uint64_t state = 12345;
  const auto uniform = [&](double a, double b) {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return a + (b - a) * double(state >> 11) / double(1ULL << 53);
  };
  struct Shape {
    double radius, corner;
  };
  int judged = 0, inside = 0;
  for (const Shape shape : {Shape{5, 0}, Shape{3, 3}, Shape{4, 1}}) {
    for (const Vec3 to : {Vec3{12, 3, 0}, Vec3{6, -4, 5}, Vec3{-3, 8, -6}}) {
      Sweep s;
      s.radius = shape.radius, s.corner = shape.corner, s.flute = 15;
      s.from = {0, 0, 0}, s.to = to;
      for (int k = 0; k < 300; ++k) {
        const double t = uniform(-0.1, 1.1);
        const Vec3 q{t * to.x + uniform(-6, 6), t * to.y + uniform(-6, 6), t * to.z + uniform(-2, 8)};
        double held = std::numeric_limits<double>::infinity();
        for (int i = 0; i <= 20000; ++i) {
          const double u = i / 20000.0;
          held = std::min(held, inner_distance(s, q.x - u * to.x, q.y - u * to.y, q.z - u * to.z) - s.corner);
        }
        const double model = outside(s, q);
        if (std::abs(held) < 0.002 || std::abs(model) < 0.002) continue;
        ++judged;
        inside += held <= 0;
        EXPECT_EQ(model <= 0, held <= 0) << "R " << shape.radius << " r " << shape.corner << " at (" << q.x << ", "
                                         << q.y << ", " << q.z << "): model " << model << ", positions " << held;
      }
    }
  }
  EXPECT_GT(judged, 2000);
  EXPECT_GT(inside, 300) << "the points straddle the sweeps";
}

// Along a vector, the cut stretch is where the points are cut: a ball along X cut by a
// vertical vector through its path meets it where the sphere does.
TEST(FinishedFacesSectionsModel, AVectorThroughABallsPathIsCutWhereTheSphereReaches) {
  Sweep s;
  s.radius = 3, s.corner = 3, s.flute = 12;
  s.from = {0, 0, 0}, s.to = {10, 0, 0};
  // Through (5, 1, z): the ball's centres run at z = 3, and the sphere reaches 3 - sqrt(9 - 1)
  // below; above, the model's cutter ends at the flute's length (12) rounded by the corner:
  // the inner segment's top, 9, plus sqrt(9 - 1).
  const auto cut = cut_stretch(s, {5, 1, 0}, {0, 0, 1}, -2, 20);
  ASSERT_TRUE(cut.has_value());
  EXPECT_NEAR(cut->first, 3 - std::sqrt(8.0), 1e-6);
  EXPECT_NEAR(cut->second, 9 + std::sqrt(8.0), 1e-6);
  EXPECT_FALSE(cut_stretch(s, {5, 3.5, 0}, {0, 0, 1}, -2, 20).has_value()) << "beside the path, clear of the cutter";
}

// ---------------------------------------------------------------------------------------
// The part planned at --tolerance 0.05, every offered plan exported and read by rs274.

struct OfferedPlan {
  std::string label;       // its steps, for the messages
  Made made;
  double reported_excess = 0, reported_gouge = 0;  // plan.json's deviation.exact
};

struct Block {
  fs::path dir;
  config::Machine machine;
  geometry::TriangleMesh mesh;
  std::vector<OfferedPlan> plans;
  std::string failure;  // why the block could not be set up
};

class FinishedFacesSections : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    block_ = new Block;
    Block& b = *block_;
    b.dir = independent::fresh_directory("hybridctl-finished-faces");
    if (const std::string missing = independent::rs274_missing(kSource); !missing.empty()) {
      b.failure = missing;
      return;
    }
    std::ostringstream tolerance;
    tolerance << kTolerance;
    const Outcome planned = run_shell(quote(HYBRIDCTL_EXE) + " plan " + quote(kPart.string()) + " --machine " +
                                          quote(kMachine.string()) + " --tolerance " + tolerance.str() +
                                          " --top 3 -o " + quote((b.dir / "plan").string()) + " --export " +
                                          quote((b.dir / "out").string()),
                                      b.dir);
    if (planned.exit_code != 0) {
      b.failure = "hybridctl plan failed:\n" + planned.out + planned.err;
      return;
    }
    b.machine = config::load_machine(kMachine);
    b.mesh = geometry::read_stl(kPart);
    const plan::PlanFile file = plan::read_plan_file(b.dir / "plan");
    const nlohmann::json json = nlohmann::json::parse(slurp(b.dir / "plan/plan.json"));
    const geometry::Box3 part = geometry::bounds(b.mesh);
    for (std::size_t k = 0; k < file.plans.size(); ++k) {
      OfferedPlan offered;
      for (const plan::PlanFileAction& a : file.plans[k].actions)
        offered.label += (offered.label.empty() ? "" : ", ") + file.primitives.at(a.primitive).label;
      // `plan --export` writes the first plan's programs; `export --plan` the others'.
      if (k > 0) {
        const Outcome exported = run_shell(quote(HYBRIDCTL_EXE) + " export " + quote((b.dir / "plan").string()) +
                                               " --plan " + std::to_string(k + 1) + " -o " + quote((b.dir / "out").string()),
                                           b.dir);
        if (exported.exit_code != 0) {
          b.failure = "hybridctl export --plan " + std::to_string(k + 1) + " failed:\n" + exported.out + exported.err;
          return;
        }
      }
      const fs::path program = b.dir / "out" / ("plan-" + std::to_string(k + 1) + ".ngc");
      const Outcome canonical = run_shell(independent::rs274_command(kSource, b.dir / "out/tool.tbl", program), b.dir);
      if (canonical.exit_code != 0) {
        b.failure = "rs274 refused " + program.filename().string() + ":\n" + canonical.err.substr(0, 2000);
        return;
      }
      offered.made = sweeps_of(canonical.out, b.machine);
      // The raw stock the plan starts from: a box round the part grown by its margins.
      const plan::PlanFilePrimitive& first = file.primitives.at(file.plans[k].actions.at(0).primitive);
      const auto stock = std::find_if(b.machine.raw_stocks.begin(), b.machine.raw_stocks.end(),
                                      [&](const config::RawStock& s) { return s.name == first.capability; });
      if (!first.raw_stock() || stock == b.machine.raw_stocks.end() || stock->kind != config::RawStock::Kind::Box)
        offered.made.unmodelled += "its start (" + first.label + ") is not a box of raw stock; ";
      else {
        const auto& m = stock->margin;
        offered.made.stock_lo = {part.min.x - m[0], part.min.y - m[1], part.min.z - m[2]};
        offered.made.stock_hi = {part.max.x + m[0], part.max.y + m[1], part.max.z + m[2]};
      }
      const nlohmann::json& exact = json["plans"][k]["deviation"]["exact"];
      offered.reported_excess = exact["max_excess_mm"].get<double>();
      offered.reported_gouge = exact["max_gouge_mm"].get<double>();
      b.plans.push_back(std::move(offered));
    }
  }
  static void TearDownTestSuite() {
    if (block_) fs::remove_all(block_->dir);
    delete block_;
    block_ = nullptr;
  }
  void SetUp() override { ASSERT_TRUE(block_->failure.empty()) << block_->failure; }

  static Block* block_;
};
Block* FinishedFacesSections::block_ = nullptr;

// A face's sections: planes across it, and which of each section's edges are the face's.
struct Face {
  const char* name;
  int axis;                       // the planes' normal: 0 x, 1 y, 2 z
  std::vector<double> planes;     // their coordinate
  bool (*on_face)(const Vec3& a, const Vec3& b, const Vec3& normal);  // the edge's ends, part frame
};

Vec3 unproject(int axis, double at, double u, double w) {
  return axis == 0 ? Vec3{at, u, w} : axis == 1 ? Vec3{u, at, w} : Vec3{u, w, at};
}

// The boss: radius 6 about (12, 12), z 8 to 15. The fillet: radius 5 about the line y = 27,
// z = 13, from y 27 to 32 and z 8 to 13, its normal towards that line. The ramp: falling 20
// degrees along +X, x 50 to 70, y 0 to 20.
const Face kFaces[] = {
    {"boss wall", 2, {9.5, 11.5, 14.0},
     [](const Vec3& a, const Vec3& b, const Vec3& n) {
       return std::abs(n.z) < 1e-6 && std::hypot(a.x - 12, a.y - 12) < 6.01 && std::hypot(b.x - 12, b.y - 12) < 6.01;
     }},
    {"fillet", 0, {5.5, 30.25, 54.5},
     [](const Vec3& a, const Vec3& b, const Vec3& n) {
       const auto on = [](const Vec3& v) { return std::abs(std::hypot(v.y - 27, v.z - 13) - 5) < 0.01; };
       return on(a) && on(b) && n.y < -1e-6 && n.z > 1e-6;
     }},
    {"ramp", 1, {3.5, 11.0, 18.5},
     [](const Vec3&, const Vec3&, const Vec3& n) {
       return std::abs(n.z - std::cos(20 * independent::kPi / 180)) < 1e-4 && n.x > 0;
     }},
};

TEST_F(FinishedFacesSections, EveryOfferedPlanMakesTheBossTheFilletAndTheRampWithinTheTolerance) {
  const Block& b = *block_;
  ASSERT_FALSE(b.plans.empty());
  for (std::size_t k = 0; k < b.plans.size(); ++k) {
    const OfferedPlan& plan = b.plans[k];
    SCOPED_TRACE("plan " + std::to_string(k + 1) + ": " + plan.label);
    ASSERT_TRUE(plan.made.unmodelled.empty()) << "the program is not what this test models: " << plan.made.unmodelled;
    double plan_excess = 0, plan_gouge = 0;
    for (const Face& face : kFaces) {
      SCOPED_TRACE(face.name);
      const auto started = std::chrono::steady_clock::now();
      std::size_t samples = 0;
      double excess = 0, gouge = 0;
      Vec3 excess_at, gouge_at;
      for (const double at : face.planes) {
        for (const independent::SectionEdge& e : independent::mesh_section(b.mesh, face.axis, at)) {
          const Vec3 a = unproject(face.axis, at, e.a0, e.b0), c = unproject(face.axis, at, e.a1, e.b1);
          if (!face.on_face(a, c, e.normal)) continue;
          const double len = std::hypot(e.a1 - e.a0, e.b1 - e.b0);
          for (double t = 0.5 * std::fmod(len, kStep); t <= len; t += kStep) {
            const double u = t / len;
            const Vec3 p{a.x + u * (c.x - a.x), a.y + u * (c.y - a.y), a.z + u * (c.z - a.z)};
            const independent::RayFigures f = measure(plan.made, b.mesh, p, e.normal);
            ++samples;
            if (f.excess > excess) excess = f.excess, excess_at = p;
            if (f.gouge > gouge) gouge = f.gouge, gouge_at = p;
          }
        }
      }
      std::cout << "[ figures  ] plan " << k + 1 << ", " << face.name << ": " << samples << " points, excess "
                << excess << " at (" << excess_at.x << ", " << excess_at.y << ", " << excess_at.z << "), gouge "
                << gouge << " at (" << gouge_at.x << ", " << gouge_at.y << ", " << gouge_at.z << "), "
                << std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count() << " s\n";
      EXPECT_GE(samples, 100u) << "the sections cross the face";
      EXPECT_LE(excess, kTolerance);
      EXPECT_LE(gouge, kTolerance);
      plan_excess = std::max(plan_excess, excess), plan_gouge = std::max(plan_gouge, gouge);
    }
    // What `plan` reported for the whole part is at least what these faces show (within the
    // sections' own 0.01 mm of agreement: they fall between the product's samples).
    EXPECT_GE(plan.reported_excess, plan_excess - 0.01);
    EXPECT_GE(plan.reported_gouge, plan_gouge - 0.01);
    EXPECT_LE(plan.reported_excess, kTolerance);
    EXPECT_LE(plan.reported_gouge, kTolerance);
  }
}

}  // namespace
