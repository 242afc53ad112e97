// Dilation by any finite offset set, voxel by voxel (the definition, for tests) and as a
// union of shifted copies of the solid's rows.

#include <map>

#include "geometry/morphology_internal.hpp"

namespace hybridctl::geometry::detail {

Solid dilate_brute_force(const Solid& solid, const std::vector<Index3>& offsets, const IndexBox& domain) {
  Solid out(solid.lattice(), domain);
  solid.for_each_voxel([&](Index3 s) {
    for (const Index3& d : offsets) {
      const Index3 p{s.x + d.x, s.y + d.y, s.z + d.z};
      if (domain.contains(p)) out.set(p);
    }
  });
  return out;
}

// The Minkowski sum as a union of shifted copies, 64 voxels a word: offsets with the
// same (dy, dz) share one pass over each source row. Cost ~ offsets x occupied rows x
// words per row, which beats the distance transforms for small beads and balls.
Solid dilate_shifts(const Solid& solid, const std::vector<Index3>& offsets, const IndexBox& source, const IndexBox& domain) {
  Solid out(solid.lattice(), domain);
  if (offsets.empty() || source.empty()) return out;
  std::map<std::pair<int, int>, std::vector<int>> by_row;  // (dy, dz) -> dx values
  for (const Index3& d : offsets) by_row[{d.y, d.z}].push_back(d.x);
  const IndexBox store = solid.storage_box();
  const int sw0 = solid.first_word(), swn = solid.words_per_row();
  const int ow0 = out.first_word(), own = out.words_per_row();
  // Which source rows hold anything, so empty space costs nothing.
  const int sy0 = source.lo.y, sny = source.hi.y - source.lo.y, snz = source.hi.z - source.lo.z;
  std::vector<std::uint8_t> occupied(std::size_t(sny) * std::size_t(snz), 0);
  tbb::parallel_for(tbb::blocked_range<int>(0, snz), [&](const tbb::blocked_range<int>& r) {
    for (int k = r.begin(); k != r.end(); ++k)
      for (int j = 0; j < sny; ++j) {
        const int y = sy0 + j, z = source.lo.z + k;
        if (y < store.lo.y || y >= store.hi.y || z < store.lo.z || z >= store.hi.z) continue;
        for (std::uint64_t w : solid.row(y, z))
          if (w) {
            occupied[std::size_t(k) * std::size_t(sny) + std::size_t(j)] = 1;
            break;
          }
      }
  });
  tbb::parallel_for(tbb::blocked_range<int>(domain.lo.z, domain.hi.z), [&](const tbb::blocked_range<int>& r) {
    for (int z = r.begin(); z != r.end(); ++z)
      for (int y = domain.lo.y; y < domain.hi.y; ++y) {
        auto dst = out.row(y, z);
        for (const auto& [dyz, dxs] : by_row) {
          const int ys = y - dyz.first, zs = z - dyz.second;
          if (ys < source.lo.y || ys >= source.hi.y || zs < source.lo.z || zs >= source.hi.z) continue;
          if (!occupied[std::size_t(zs - source.lo.z) * std::size_t(sny) + std::size_t(ys - sy0)]) continue;
          const auto src = solid.row(ys, zs);
          for (int dx : dxs) {
            // Output voxel x takes source voxel x - dx.
            const int q = dx >= 0 ? dx / 64 : -((-dx + 63) / 64);
            const int rbits = dx - q * 64;  // 0..63
            for (int w = 0; w < own; ++w) {
              const int sword = ow0 + w - q - sw0;  // index into src of the word shifted up by rbits
              std::uint64_t v = 0;
              if (sword >= 0 && sword < swn) v = src[std::size_t(sword)] << rbits;
              if (rbits && sword - 1 >= 0 && sword - 1 < swn) v |= src[std::size_t(sword - 1)] >> (64 - rbits);
              dst[std::size_t(w)] |= v;
            }
          }
        }
      }
  });
  // Shifts may reach past the domain inside the last word; clip.
  return intersect(out, Solid::filled(solid.lattice(), domain));
}

}  // namespace hybridctl::geometry::detail
