#include "independent_part.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include <unistd.h>

namespace hybridctl::verification::independent {
namespace {

std::vector<std::string> arguments(const std::string& line) {
  const std::size_t open = line.find('('), close = line.rfind(')');
  std::vector<std::string> out;
  std::stringstream s(line.substr(open + 1, close - open - 1));
  for (std::string item; std::getline(s, item, ',');) out.push_back(item);
  return out;
}

double number(const std::string& s) { return std::stod(s); }

Vec3 sub(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
double dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
Vec3 lerp(Vec3 a, Vec3 b, double t) { return {a.x + t * (b.x - a.x), a.y + t * (b.y - a.y), a.z + t * (b.z - a.z)}; }

}  // namespace

CanonicalProgram read_canonical(const std::string& text) {
  CanonicalProgram out;
  Vec3 at;
  bool known = false;  // where the tool is
  int selected = 0, tool = 0, offset = 54, action = 0;
  bool xy_plane = true;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    const std::size_t open = line.find('(');
    if (open == std::string::npos) continue;
    const std::size_t start = line.rfind(' ', open) + 1;
    const std::string call = line.substr(start, open - start);
    if (call == "COMMENT") {
      int k = 0;
      if (std::sscanf(line.c_str() + open, "(\"action %d:", &k) == 1) action = k;
      continue;
    }
    if (call == "SELECT_TOOL") selected = int(number(arguments(line)[0]));
    if (call == "CHANGE_TOOL") tool = selected;
    if (call == "SET_G5X_OFFSET") offset = 53 + int(number(arguments(line)[0]));
    if (call == "SELECT_PLANE") xy_plane = line.find("CANON_PLANE_XY") != std::string::npos;
    if (call == "SET_AUX_OUTPUT_BIT") ++out.deposits;
    const bool line_move = call == "STRAIGHT_TRAVERSE" || call == "STRAIGHT_FEED";
    if (!line_move && call != "ARC_FEED") continue;
    const std::vector<std::string> a = arguments(line);
    CanonicalMove move;
    move.tool = tool, move.work_offset = offset, move.action = action;
    move.feed = call != "STRAIGHT_TRAVERSE";
    if (line_move) {
      move.to = {number(a[0]), number(a[1]), number(a[2])};
    } else {
      if (!xy_plane) {
        ++out.other_planes;
        known = false;
        continue;
      }
      move.to = {number(a[0]), number(a[1]), number(a[5])};
      move.arc = true;
      move.cx = number(a[2]), move.cy = number(a[3]);
      const int turns = int(number(a[4]));
      if (known) {
        move.r = std::hypot(at.x - move.cx, at.y - move.cy);
        move.a0 = std::atan2(at.y - move.cy, at.x - move.cx);
        const double a1 = std::atan2(move.to.y - move.cy, move.to.x - move.cx);
        // rs274: the sign of `turns` is the direction, |turns| - 1 the whole turns added.
        double d = turns > 0 ? a1 - move.a0 : move.a0 - a1;
        while (d <= 1e-12) d += 2 * kPi;
        d += (std::abs(turns) - 1) * 2 * kPi;
        move.sweep = turns > 0 ? d : -d;
      }
    }
    move.from = at;
    if (known) out.moves.push_back(move);
    at = move.to, known = true;
  }
  return out;
}

std::filesystem::path fresh_directory(const std::string& prefix) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / (prefix + "-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

std::string rs274_missing(const std::filesystem::path& source) {
  if (std::filesystem::exists(source / ".peers/linuxcnc/usr/bin/rs274")) return {};
  return "LinuxCNC's rs274 is missing from .peers/linuxcnc: run scripts/setup (it downloads linuxcnc-uspace and "
         "libboost-python1.74.0 with apt-get download and unpacks them there)";
}

std::string rs274_command(const std::filesystem::path& source, const std::filesystem::path& tool_table,
                          const std::filesystem::path& program) {
  const auto quoted = [](const std::filesystem::path& p) { return "'" + p.string() + "'"; };
  return quoted(source / "scripts/rs274") + " -t " + quoted(tool_table) + " -g " + quoted(program);
}

Vec3 closest_on_triangle(Vec3 p, Vec3 a, Vec3 b, Vec3 c) {
  const Vec3 ab = sub(b, a), ac = sub(c, a), ap = sub(p, a);
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vec3 bp = sub(p, b);
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return lerp(a, b, d1 / (d1 - d3));
  const Vec3 cp = sub(p, c);
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return lerp(a, c, d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) return lerp(b, c, (d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const double denom = 1 / (va + vb + vc);
  const double v = vb * denom, w = vc * denom;
  return {a.x + ab.x * v + ac.x * w, a.y + ab.y * v + ac.y * w, a.z + ab.z * v + ac.z * w};
}

double mesh_distance(const geometry::TriangleMesh& mesh, Vec3 p) {
  double best = std::numeric_limits<double>::infinity();
  for (const geometry::Triangle& t : mesh.triangles) {
    const Vec3 q = closest_on_triangle(p, t[0], t[1], t[2]);
    best = std::min(best, std::sqrt(dot(sub(p, q), sub(p, q))));
  }
  return best;
}

std::vector<SectionEdge> mesh_section(const geometry::TriangleMesh& mesh, int axis, double at) {
  const auto coordinate = [](const Vec3& v, int k) { return k == 0 ? v.x : k == 1 ? v.y : v.z; };
  const int u = axis == 0 ? 1 : 0, w = axis == 2 ? 1 : 2;
  std::vector<SectionEdge> out;
  for (const geometry::Triangle& t : mesh.triangles) {
    std::vector<std::pair<double, double>> points;
    for (int i = 0; i < 3; ++i) {
      const Vec3 a = t[i], b = t[(i + 1) % 3];
      const double ha = coordinate(a, axis) - at, hb = coordinate(b, axis) - at;
      if (ha * hb < 0) {
        const Vec3 q = lerp(a, b, ha / (ha - hb));
        points.push_back({coordinate(q, u), coordinate(q, w)});
      }
    }
    if (points.size() != 2) continue;
    const Vec3 e1 = sub(t[1], t[0]), e2 = sub(t[2], t[0]);
    Vec3 n{e1.y * e2.z - e1.z * e2.y, e1.z * e2.x - e1.x * e2.z, e1.x * e2.y - e1.y * e2.x};
    const double len = std::sqrt(dot(n, n));
    if (len == 0) continue;
    n = {n.x / len, n.y / len, n.z / len};
    out.push_back({points[0].first, points[0].second, points[1].first, points[1].second, n});
  }
  return out;
}

double segment_distance_2d(double px, double py, double ax, double ay, double bx, double by) {
  const double vx = bx - ax, vy = by - ay, l2 = vx * vx + vy * vy;
  const double t = l2 > 0 ? std::clamp(((px - ax) * vx + (py - ay) * vy) / l2, 0.0, 1.0) : 0.0;
  return std::hypot(px - ax - t * vx, py - ay - t * vy);
}

RayFigures ray_figures(const geometry::TriangleMesh& mesh, Vec3 p, Vec3 n, double inward, double s0,
                       double s1, std::vector<Removal> removed) {
  const double lo = -inward;
  // Runs of material: [s0, s1] less the union of the removed intervals.
  std::sort(removed.begin(), removed.end(), [](const Removal& a, const Removal& b) { return a.lo < b.lo; });
  struct Run {
    double lo, hi;
    std::set<int> hi_actions;
  };
  std::vector<Run> runs;
  double from = s0;
  std::size_t k = 0;
  while (from < s1) {
    // The next removal that reaches past `from`.
    while (k < removed.size() && removed[k].hi <= from) ++k;
    if (k == removed.size()) {
      runs.push_back({from, s1, {0}});
      break;
    }
    if (removed[k].lo > from) {
      const double end = std::min(removed[k].lo, s1);
      std::set<int> by;
      for (const Removal& r : removed)
        if (std::abs(r.lo - end) < 1e-7) by.insert(r.action);
      runs.push_back({from, end, end < s1 ? by : std::set<int>{0}});
    }
    // Skip the covered stretch: removals chained from here on.
    double covered = std::max(from, removed[k].hi);
    for (std::size_t j = k; j < removed.size() && removed[j].lo <= covered; ++j)
      covered = std::max(covered, removed[j].hi);
    from = covered;
  }
  RayFigures f;
  const auto at = [&](double s) { return Vec3{p.x + s * n.x, p.y + s * n.y, p.z + s * n.z}; };
  if (!runs.empty() && runs.back().hi > 1e-9) f.excess = mesh_distance(mesh, at(runs.back().hi));
  const Run* under = nullptr;
  for (const Run& r : runs)
    if (r.lo <= 0) under = &r;
  double deepest = 1;
  if (!under) deepest = lo;
  else if (under->hi < -1e-9) deepest = under->hi;
  if (deepest < 0) f.gouge = mesh_distance(mesh, at(deepest));
  f.surface_actions = under ? under->hi_actions : std::set<int>{};
  return f;
}

}  // namespace hybridctl::verification::independent
