#include "report/report_mesh.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <unordered_map>

#include "geometry/surface_mesh.hpp"

namespace hybridctl::report {
namespace {

using geometry::Index3;
using geometry::IndexBox;
using geometry::Solid;

int floor_div(int a, int b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

// Faces between a voxel of the solid and air: what the surface is made of.
std::int64_t exposed_faces(const Solid& solid) {
  const IndexBox box = solid.bounding_box();
  if (box.empty()) return 0;
  std::int64_t faces = 0;
  const int w0 = solid.first_word(), words = solid.words_per_row();
  for (int z = box.lo.z; z < box.hi.z; ++z)
    for (int y = box.lo.y; y < box.hi.y; ++y)
      for (int w = w0; w < w0 + words; ++w) {
        const std::uint64_t a = solid.word_at(w, y, z);
        if (!a) continue;
        const std::uint64_t prev = solid.word_at(w - 1, y, z), next = solid.word_at(w + 1, y, z);
        faces += std::popcount(a & ~((a << 1) | (prev >> 63))) + std::popcount(a & ~((a >> 1) | (next << 63)));
        faces += std::popcount(a & ~solid.word_at(w, y - 1, z)) + std::popcount(a & ~solid.word_at(w, y + 1, z));
        faces += std::popcount(a & ~solid.word_at(w, y, z - 1)) + std::popcount(a & ~solid.word_at(w, y, z + 1));
      }
  return faces;
}

struct VertexKey {
  float x, y, z;
  bool operator==(const VertexKey& o) const { return x == o.x && y == o.y && z == o.z; }
};
struct VertexHash {
  std::size_t operator()(const VertexKey& k) const {
    std::uint32_t b[3];
    std::memcpy(b, &k, sizeof b);
    return (std::size_t(b[0]) * 73856093u) ^ (std::size_t(b[1]) * 19349663u) ^ (std::size_t(b[2]) * 83492791u);
  }
};

}  // namespace

IndexedMesh indexed_mesh(const geometry::TriangleMesh& mesh, double voxel_size) {
  IndexedMesh out;
  out.voxel_size = voxel_size;
  std::unordered_map<VertexKey, std::uint32_t, VertexHash> index;
  index.reserve(mesh.triangles.size());
  out.indices.reserve(mesh.triangles.size() * 3);
  for (const geometry::Triangle& t : mesh.triangles)
    for (const geometry::Vec3& p : t) {
      const VertexKey key{float(p.x), float(p.y), float(p.z)};
      const auto [it, added] = index.try_emplace(key, std::uint32_t(out.positions.size() / 3));
      if (added) out.positions.insert(out.positions.end(), {key.x, key.y, key.z});
      out.indices.push_back(it->second);
    }
  return out;
}

namespace {

// Flat regions merge into larger polygons; the voxel staircase on slopes stays.
constexpr double kAdaptivity = 0.5;
constexpr int kMaxCoarsening = 16;

}  // namespace

Solid coarsen(const Solid& solid, int factor) {
  if (factor <= 1) return solid;
  geometry::Lattice coarse = solid.lattice();
  coarse.voxel_size *= factor;
  const IndexBox box = solid.bounding_box();
  if (box.empty()) return Solid(coarse, {});
  const IndexBox cbox{{floor_div(box.lo.x, factor), floor_div(box.lo.y, factor), floor_div(box.lo.z, factor)},
                      {floor_div(box.hi.x - 1, factor) + 1, floor_div(box.hi.y - 1, factor) + 1,
                       floor_div(box.hi.z - 1, factor) + 1}};
  const int nx = cbox.hi.x - cbox.lo.x, ny = cbox.hi.y - cbox.lo.y;
  std::vector<std::int32_t> counts(std::size_t(cbox.voxel_count()), 0);
  for (int z = box.lo.z; z < box.hi.z; ++z)
    for (int y = box.lo.y; y < box.hi.y; ++y) {
      const std::size_t row = (std::size_t(floor_div(z, factor) - cbox.lo.z) * ny + (floor_div(y, factor) - cbox.lo.y)) * nx;
      for (int w = solid.first_word(); w < solid.first_word() + solid.words_per_row(); ++w)
        for (std::uint64_t bits = solid.word_at(w, y, z); bits; bits &= bits - 1) {
          const int x = w * Solid::kWordBits + std::countr_zero(bits);
          ++counts[row + std::size_t(floor_div(x, factor) - cbox.lo.x)];
        }
    }
  const int half = (factor * factor * factor + 1) / 2;
  Solid out(coarse, cbox);
  for (int z = 0; z < cbox.hi.z - cbox.lo.z; ++z)
    for (int y = 0; y < ny; ++y)
      for (int x = 0; x < nx; ++x)
        if (counts[(std::size_t(z) * ny + y) * nx + x] >= half) out.set({x + cbox.lo.x, y + cbox.lo.y, z + cbox.lo.z});
  return out;
}

IndexedMesh budget_mesh(const Solid& solid, std::size_t triangle_budget) {
  if (solid.empty()) return IndexedMesh{{}, {}, solid.voxel_size()};
  // Two triangles per exposed face without merging; merging flat faces usually saves
  // three quarters of them, so the first guess assumes that and the next one corrects it.
  const double estimate = 2.0 * double(exposed_faces(solid)) / 4.0;
  const double budget = double(std::max<std::size_t>(triangle_budget, 12));
  int factor = std::clamp(int(std::ceil(std::sqrt(estimate / budget))), 1, kMaxCoarsening);
  for (;;) {
    const Solid meshed = coarsen(solid, factor);
    geometry::TriangleMesh mesh = geometry::surface_mesh(meshed, kAdaptivity, geometry::SurfaceMethod::Occupancy);
    if (mesh.triangles.size() <= triangle_budget || factor >= kMaxCoarsening || meshed.empty())
      return indexed_mesh(mesh, meshed.voxel_size());
    // Triangles shrink with the square of the voxel size.
    const double ratio = std::sqrt(double(mesh.triangles.size()) / budget);
    factor = std::min(kMaxCoarsening, std::max(factor + 1, int(std::ceil(factor * ratio * 1.05))));
  }
}

std::string base64(const void* data, std::size_t bytes) {
  static constexpr char kDigits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  const auto* p = static_cast<const unsigned char*>(data);
  std::string out;
  out.reserve((bytes + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < bytes; i += 3) {
    const std::uint32_t n = (std::uint32_t(p[i]) << 16) | (std::uint32_t(p[i + 1]) << 8) | p[i + 2];
    out += kDigits[n >> 18];
    out += kDigits[(n >> 12) & 63];
    out += kDigits[(n >> 6) & 63];
    out += kDigits[n & 63];
  }
  if (i < bytes) {
    std::uint32_t n = std::uint32_t(p[i]) << 16;
    if (i + 1 < bytes) n |= std::uint32_t(p[i + 1]) << 8;
    out += kDigits[n >> 18];
    out += kDigits[(n >> 12) & 63];
    out += i + 1 < bytes ? kDigits[(n >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

}  // namespace hybridctl::report
