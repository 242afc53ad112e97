#include <algorithm>
#include <bit>
#include <cmath>
#include <sstream>
#include <unordered_map>

#include "common/error.hpp"
#include "geometry/mesh.hpp"

namespace hybridctl::geometry {
namespace {

bool less(const Vec3& a, const Vec3& b) {
  if (a.x != b.x) return a.x < b.x;
  if (a.y != b.y) return a.y < b.y;
  return a.z < b.z;
}

// Hashes what Vec3's == compares: the numbers, so -0 and 0 (equal, different bits; STL
// exporters write either) hash alike.
struct VertexHash {
  static std::uint64_t bits(double c) { return std::bit_cast<std::uint64_t>(c + 0.0); }  // -0 + 0 is +0
  std::size_t operator()(const Vec3& v) const {
    std::uint64_t h = bits(v.x) * 0x9E3779B97F4A7C15ull;
    h ^= bits(v.y) + 0x7F4A7C159E3779B9ull + (h << 6) + (h >> 2);
    h ^= bits(v.z) + 0x94D049BB133111EBull + (h << 6) + (h >> 2);
    return std::size_t(h);
  }
};

std::string point(const Vec3& v) {
  std::ostringstream os;
  os << "(" << v.x << ", " << v.y << ", " << v.z << ")";
  return os.str();
}

}  // namespace

TriangleMesh clean_mesh(const TriangleMesh& mesh, MeshReport* report) {
  MeshReport r;
  r.triangles = mesh.triangles.size();

  // Drop degenerate facets and collapse repeated ones (either winding) by sorting each
  // facet's vertices into a canonical key.
  struct Keyed {
    Triangle key;
    std::size_t index;
  };
  std::vector<Keyed> keyed;
  keyed.reserve(mesh.triangles.size());
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
    Triangle key = mesh.triangles[i];
    std::sort(key.begin(), key.end(), less);
    if (key[0] == key[1] || key[1] == key[2]) {
      ++r.degenerate_facets;
      continue;
    }
    keyed.push_back({key, i});
  }
  auto key_less = [](const Keyed& a, const Keyed& b) {
    for (int v = 0; v < 3; ++v) {
      if (less(a.key[v], b.key[v])) return true;
      if (less(b.key[v], a.key[v])) return false;
    }
    return a.index < b.index;
  };
  std::sort(keyed.begin(), keyed.end(), key_less);
  TriangleMesh out;
  out.triangles.reserve(keyed.size());
  std::vector<std::size_t> kept;
  for (std::size_t i = 0; i < keyed.size(); ++i) {
    if (i > 0 && keyed[i].key == keyed[i - 1].key) {
      ++r.duplicate_facets;
      continue;
    }
    kept.push_back(keyed[i].index);
  }
  std::sort(kept.begin(), kept.end());  // keep the file's order
  for (std::size_t i : kept) out.triangles.push_back(mesh.triangles[i]);

  // Edge census on welded vertices (identical coordinates are one vertex, as in STL).
  std::unordered_map<Vec3, std::uint32_t, VertexHash> ids;
  std::vector<Vec3> vertices;
  std::vector<std::uint64_t> edges;
  edges.reserve(out.triangles.size() * 3);
  auto id_of = [&](const Vec3& v) {
    auto [it, inserted] = ids.try_emplace(v, std::uint32_t(vertices.size()));
    if (inserted) vertices.push_back(v);
    return it->second;
  };
  for (const Triangle& t : out.triangles) {
    const std::uint32_t a = id_of(t[0]), b = id_of(t[1]), c = id_of(t[2]);
    for (auto [p, q] : {std::pair{a, b}, std::pair{b, c}, std::pair{c, a}}) {
      edges.push_back((std::uint64_t(std::min(p, q)) << 32) | std::max(p, q));
    }
  }
  std::sort(edges.begin(), edges.end());
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && edges[j] == edges[i]) ++j;
    const std::size_t uses = j - i;
    if (uses % 2 == 1) {
      if (r.boundary_edges == 0) {
        r.first_boundary_edge = {vertices[edges[i] >> 32], vertices[edges[i] & 0xffffffffu]};
      }
      ++r.boundary_edges;
    }
    if (uses > 2) ++r.nonmanifold_edges;
    i = j;
  }
  if (report) *report = r;
  return out;
}

void require_closed(const MeshReport& report, const std::string& name) {
  if (report.closed()) return;
  throw InputError(name + ": open mesh: " + std::to_string(report.boundary_edges) +
                   " boundary edge" + (report.boundary_edges == 1 ? "" : "s") + " (first between " +
                   point(report.first_boundary_edge[0]) + " and " + point(report.first_boundary_edge[1]) +
                   "); expected a closed surface. hybridctl does not guess how to fill holes: repair "
                   "the mesh in CAD and export it again");
}

std::vector<Triangle> axis_square_faces(const TriangleMesh& mesh) {
  const bool inverted = signed_volume(mesh) < 0;
  std::vector<Triangle> out;
  for (const Triangle& t : mesh.triangles) {
    const bool square = (t[0].x == t[1].x && t[1].x == t[2].x) || (t[0].y == t[1].y && t[1].y == t[2].y) ||
                        (t[0].z == t[1].z && t[1].z == t[2].z);
    if (!square) continue;
    out.push_back(inverted ? Triangle{t[0], t[2], t[1]} : t);
  }
  return out;
}

double signed_volume(const TriangleMesh& mesh) {
  // Relative to the first vertex, to keep the determinants small and well-conditioned.
  if (mesh.triangles.empty()) return 0;
  const Vec3 o = mesh.triangles[0][0];
  double six_v = 0;
  for (const Triangle& t : mesh.triangles) {
    const Vec3 a{t[0].x - o.x, t[0].y - o.y, t[0].z - o.z};
    const Vec3 b{t[1].x - o.x, t[1].y - o.y, t[1].z - o.z};
    const Vec3 c{t[2].x - o.x, t[2].y - o.y, t[2].z - o.z};
    six_v += a.x * (b.y * c.z - b.z * c.y) - a.y * (b.x * c.z - b.z * c.x) + a.z * (b.x * c.y - b.y * c.x);
  }
  return six_v / 6.0;
}

Box3 bounds(const TriangleMesh& mesh) {
  if (mesh.triangles.empty()) return {};
  Box3 b{mesh.triangles[0][0], mesh.triangles[0][0]};
  for (const Triangle& t : mesh.triangles)
    for (const Vec3& v : t) {
      b.min = {std::min(b.min.x, v.x), std::min(b.min.y, v.y), std::min(b.min.z, v.z)};
      b.max = {std::max(b.max.x, v.x), std::max(b.max.y, v.y), std::max(b.max.z, v.z)};
    }
  return b;
}

}  // namespace hybridctl::geometry
