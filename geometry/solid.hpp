#pragma once
// The voxel solid every other module sees: a set of voxels on a lattice.
//
// A Lattice fixes the voxel size h and the position of voxel (0,0,0): voxel (i,j,k)
// is the cube origin + [i,i+1) x [j,j+1) x [k,k+1) times h, with its centre at
// origin + (i+0.5, j+0.5, k+0.5) h. Solids combine only when they share a lattice, so
// a job voxelizes every part, primitive and stock on one lattice.
//
// Storage is dense bits, 64 voxels of one X row per word, over a storage box whose X
// extent is word-aligned. docs/design/solid-storage.md says why (measured against an
// OpenVDB bool tree). Nothing outside geometry/ depends on the layout except through
// the row accessors, which exist for the fast loops of morphology and the planner.

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

namespace hybridctl::geometry {

struct Vec3 {
  double x = 0, y = 0, z = 0;
  friend bool operator==(const Vec3&, const Vec3&) = default;
};

struct Index3 {
  int x = 0, y = 0, z = 0;
  friend bool operator==(const Index3&, const Index3&) = default;
};

// Half-open box of voxel indices [lo, hi).
struct IndexBox {
  Index3 lo, hi;
  bool empty() const { return hi.x <= lo.x || hi.y <= lo.y || hi.z <= lo.z; }
  std::int64_t voxel_count() const {
    return empty() ? 0 : std::int64_t(hi.x - lo.x) * (hi.y - lo.y) * (hi.z - lo.z);
  }
  bool contains(Index3 p) const {
    return p.x >= lo.x && p.x < hi.x && p.y >= lo.y && p.y < hi.y && p.z >= lo.z && p.z < hi.z;
  }
  friend bool operator==(const IndexBox&, const IndexBox&) = default;
};
IndexBox box_union(const IndexBox& a, const IndexBox& b);
IndexBox box_intersection(const IndexBox& a, const IndexBox& b);

// Axis-aligned box in mm.
struct Box3 {
  Vec3 min, max;
  Vec3 size() const { return {max.x - min.x, max.y - min.y, max.z - min.z}; }
};

struct Lattice {
  double voxel_size = 1.0;  // mm, > 0
  Vec3 origin;              // mm position of the min corner of voxel (0,0,0)

  Vec3 center(Index3 v) const {
    return {origin.x + (v.x + 0.5) * voxel_size, origin.y + (v.y + 0.5) * voxel_size,
            origin.z + (v.z + 0.5) * voxel_size};
  }
  // The voxels whose centres lie in [min, max] (closed) of a mm box.
  IndexBox centers_within(const Box3& box) const;
  // The mm extent of a box of voxels.
  Box3 extent(const IndexBox& box) const;
  friend bool operator==(const Lattice&, const Lattice&) = default;
};

class Solid {
 public:
  static constexpr int kWordBits = 64;

  // An empty solid on a unit lattice; assign a real one before use.
  Solid() = default;
  // An empty solid whose storage covers `domain` (grown to whole words along X).
  Solid(Lattice lattice, IndexBox domain);
  // Every voxel of `domain` set.
  static Solid filled(Lattice lattice, IndexBox domain);

  const Lattice& lattice() const { return lattice_; }
  double voxel_size() const { return lattice_.voxel_size; }
  // Where voxels may be set: a superset of bounding_box(), X word-aligned.
  IndexBox storage_box() const;

  bool contains(Index3 v) const;  // false outside storage
  // Sets or clears one voxel; throws std::out_of_range outside the storage box.
  void set(Index3 v, bool occupied = true);
  // Sets voxels [x0, x1) of row (y, z); the range must lie in the storage box.
  void set_run(int y, int z, int x0, int x1);

  std::int64_t voxel_count() const;
  double volume() const;  // mm^3
  bool empty() const {
    for (std::uint64_t w : words_)
      if (w) return false;
    return true;
  }
  // Tight box of the occupied voxels; empty box when the solid is empty.
  IndexBox bounding_box() const;
  Box3 bounding_box_mm() const { return lattice_.extent(bounding_box()); }

  // Calls fn(Index3) for every occupied voxel, in z, y, x order.
  void for_each_voxel(const std::function<void(Index3)>& fn) const;

  // Row access for fast loops: the words of row (y, z); word w holds voxels
  // x = (first_word() + w) * 64 + bit. Rows outside storage are not accessible.
  int first_word() const { return wx0_; }
  int words_per_row() const { return wx1_ - wx0_; }
  std::span<const std::uint64_t> row(int y, int z) const;
  std::span<std::uint64_t> row(int y, int z);
  // The 64 voxels x = word * 64 ... word * 64 + 63 of row (y, z); 0 outside storage.
  std::uint64_t word_at(int word, int y, int z) const {
    if (words_.empty() || y < y0_ || y >= y1_ || z < z0_ || z >= z1_ || word < wx0_ || word >= wx1_) return 0;
    return words_[row_offset(y, z) + std::size_t(word - wx0_)];
  }

  // Same lattice and same occupied voxels (storage boxes may differ).
  friend bool operator==(const Solid& a, const Solid& b);

 private:
  std::size_t row_offset(int y, int z) const {
    return (std::size_t(z - z0_) * std::size_t(y1_ - y0_) + std::size_t(y - y0_)) *
           std::size_t(wx1_ - wx0_);
  }
  friend Solid combine_words(const Solid&, const Solid&, IndexBox, int op);

  Lattice lattice_;
  int wx0_ = 0, wx1_ = 0;  // word range along X
  int y0_ = 0, y1_ = 0, z0_ = 0, z1_ = 0;
  std::vector<std::uint64_t> words_;
};

// Constructive solid geometry. Both operands must share a lattice (std::invalid_argument
// otherwise). Results are new values; operands are untouched.
Solid unite(const Solid& a, const Solid& b);
Solid intersect(const Solid& a, const Solid& b);
Solid subtract(const Solid& a, const Solid& b);  // a minus b
// The voxels of `domain` not in `a`.
Solid complement(const Solid& a, const IndexBox& domain);
// The voxels of `a` inside `box`, stored over `box` on `lattice`, by their indices: for a
// solid whose lattice differs from the one wanted only by the rounding of its origin (read
// back from a .vdb) or that lies in another frame's box.
Solid copied_onto(const Solid& a, const Lattice& lattice, const IndexBox& box);

enum class Axis { X, Y, Z };

// Moves every voxel by a whole number of voxels.
Solid translate(const Solid& a, Index3 offset);
// Moves by a distance in mm, which must be a whole number of voxels
// (std::invalid_argument otherwise: resampling would change the shape).
Solid translate_mm(const Solid& a, Vec3 offset_mm);
// Rotates by quarter_turns * 90 degrees (right-handed) about `axis` through the
// lattice origin; exact, since the lattice maps onto itself.
Solid rotate_quarter_turns(const Solid& a, Axis axis, int quarter_turns);

}  // namespace hybridctl::geometry
