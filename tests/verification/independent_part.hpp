#pragma once
// LinuxCNC's rs274 reading of an exported program, and the design's triangles, for the
// tests that measure a part made by another road than the product's: what the interpreter
// says each move is (its canonical calls), with the tool, work offset and action it runs
// with; distances to the STL and its sections by brute force over the triangles.
//
// rs274 runs without offsets, so its canonical coordinates are the program's, which are
// the work frame's of the setup whose work offset is active (docs/machine-file.md: program
// coordinates + work_origin = machine coordinates); it prints them to 4 decimals. Its G53
// retracts (machine Z 300) read as work Z 300: far above any part here.

#include <filesystem>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "geometry/mesh.hpp"

namespace hybridctl::verification::independent {

using geometry::Vec3;

inline constexpr double kPi = 3.14159265358979323846;

// One move as rs274 reads it. A move's start is where the previous one ended; the first
// move starts at rs274's assumed origin, which the program never commanded, so it is not
// returned.
struct CanonicalMove {
  int tool = 0;           // the T number in the spindle (CHANGE_TOOL), 0 for none
  int work_offset = 54;   // G54.. (SET_G5X_OFFSET)
  int action = 0;         // the last heading comment's number ("action N: ...")
  bool feed = false;      // STRAIGHT_FEED or ARC_FEED; STRAIGHT_TRAVERSE otherwise
  Vec3 from, to;
  bool arc = false;
  // Arcs (XY plane): centre, radius, start angle and signed sweep (counter-clockwise > 0);
  // z goes linearly with the angle from from.z to to.z.
  double cx = 0, cy = 0, r = 0, a0 = 0, sweep = 0;
};

struct CanonicalProgram {
  std::vector<CanonicalMove> moves;
  int deposits = 0;      // SET_AUX_OUTPUT_BIT: a head's output on (M64)
  int other_planes = 0;  // arcs out of the XY plane (not returned)
};

// rs274's standard output (scripts/rs274 -g).
CanonicalProgram read_canonical(const std::string& text);

// An empty directory of its own under the system's temporary one: `prefix`-<pid>.
std::filesystem::path fresh_directory(const std::string& prefix);

// Empty when scripts/setup has unpacked LinuxCNC's rs274 into the source tree's
// .peers/linuxcnc; else what is missing and how to get it (a failure, never a skip).
std::string rs274_missing(const std::filesystem::path& source);
// The shell command that prints rs274's canonical calls for `program` with `tool_table`.
std::string rs274_command(const std::filesystem::path& source, const std::filesystem::path& tool_table,
                          const std::filesystem::path& program);

// The point of a triangle nearest to p (Ericson, Real-Time Collision Detection, 5.1.5).
Vec3 closest_on_triangle(Vec3 p, Vec3 a, Vec3 b, Vec3 c);
// The distance from p to the nearest of the mesh's triangles.
double mesh_distance(const geometry::TriangleMesh& mesh, Vec3 p);

// The mesh cut by a plane, as segments in the plane's two coordinates, each with the unit
// normal of the triangle it comes from. `axis` is the plane's normal (0 x, 1 y, 2 z) and
// `at` its coordinate; the segment's coordinates are the other two in order (x, y for a
// horizontal plane; y, z for x = const; x, z for y = const).
struct SectionEdge {
  double a0, b0, a1, b1;  // from (a0, b0) to (a1, b1)
  Vec3 normal;            // the triangle's, part frame
};
std::vector<SectionEdge> mesh_section(const geometry::TriangleMesh& mesh, int axis, double at);

double segment_distance_2d(double px, double py, double ax, double ay, double bx, double by);

// ---------------------------------------------------------------------------------------
// The part made, along one sample's vector: p + s n for s in [-inward, outward], n the
// design's outward normal at p.

// A stretch of the vector a cut removed.
struct Removal {
  double lo = 0, hi = 0;
  int action = 0;
};

// Excess and gouge as docs/verification.md defines them: the material standing out of the
// design (from the outermost point of material along the vector, its distance to the STL)
// and the air under its surface (from the deepest point of air under p). The material is
// the stock's stretch [s0, s1] less every removal (no bead: the order of the cuts does not
// matter). s1 is where the vector ends, at most its outward reach.
struct RayFigures {
  double excess = 0, gouge = 0;
  std::set<int> surface_actions;  // whose cut made the surface under p (0: the stock)
};
RayFigures ray_figures(const geometry::TriangleMesh& mesh, Vec3 p, Vec3 n, double inward, double s0,
                       double s1, std::vector<Removal> removed);

}  // namespace hybridctl::verification::independent
