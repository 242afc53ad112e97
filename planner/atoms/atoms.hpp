#pragma once
// Atoms (the paper's canonical intersection terms, section 6): every voxel of the
// planning domain gets an n-bit code saying which primitives contain it, and voxels
// with equal codes form one atom. Atoms are the smallest units any plan can deposit or
// remove, so a design is makeable only as a union of whole atoms.
//
// The decomposition is built incrementally: adding a primitive splits each atom it
// partly covers into the part inside and the part outside (section 8), and gives the
// same partition as a recompute from scratch.

#include <cstdint>
#include <vector>

#include "geometry/solid.hpp"
#include "planner/problem/atom_set.hpp"
#include "planner/atoms/tolerance_zone.hpp"

namespace hybridctl::planner {

using geometry::Index3;
using geometry::IndexBox;
using geometry::Lattice;
using geometry::Solid;
using geometry::Vec3;

class AtomDecomposition {
 public:
  // One atom (code 0...0) covering `domain`, before any primitive.
  AtomDecomposition(const Lattice& lattice, const IndexBox& domain);
  // Decomposes the domain by all `primitives` at once (the reference computation).
  static AtomDecomposition recompute(const Lattice& lattice, const IndexBox& domain,
                                     const std::vector<const Solid*>& primitives);

  // Splits every atom by one more primitive; parts of it outside the domain are ignored.
  void add_primitive(const Solid& primitive);

  int primitive_count() const { return primitives_; }
  int atom_count() const { return int(codes_.size()); }
  // The atom's membership code: the primitives it lies inside.
  const AtomSet& code(int atom) const { return codes_[std::size_t(atom)]; }
  const Lattice& lattice() const { return lattice_; }
  const IndexBox& domain() const { return domain_; }
  // The atom of a voxel of the domain.
  int atom_at(Index3 v) const;
  // The same without the range check; x counted from the domain's low x.
  int atom_at_unchecked(int x_from_low, int y, int z) const {
    const std::size_t nx = std::size_t(domain_.hi.x - domain_.lo.x), ny = std::size_t(domain_.hi.y - domain_.lo.y);
    return labels_[(std::size_t(z - domain_.lo.z) * ny + std::size_t(y - domain_.lo.y)) * nx + std::size_t(x_from_low)];
  }
  // The voxels of one atom, or of a set of atoms (selected[atom] true), as a solid.
  Solid atom_solid(int atom) const;
  Solid union_of(const std::vector<bool>& selected) const;

  // Same partition, same codes (atom numbering may differ).
  friend bool same_partition(const AtomDecomposition& a, const AtomDecomposition& b);

 private:
  template <typename Fn>
  void for_each_voxel_label(Fn fn) const;

  Lattice lattice_;
  IndexBox domain_;
  int primitives_ = 0;
  std::vector<AtomSet> codes_;
  std::vector<std::int32_t> labels_;  // atom per domain voxel, x fastest
};

// What an atom is to the design, given the tolerance zone (section 6, relaxed; two-sided,
// planner/atoms/tolerance_zone.hpp): a must-in atom reaches the design shrunk by the tolerance
// or is needed to keep a thin feature (planner/atoms/thin_parts.hpp), a must-out atom reaches
// beyond the design grown by the tolerance or is needed to keep a narrow gap open, a
// violating atom is both, and a free atom neither. Slivers (below the volume threshold)
// are discretization noise and count as free: the one case where an outcome that
// respects the classes may still be outside the tolerance.
enum class AtomClass { MustIn, MustOut, Free, Violating };
const char* to_string(AtomClass c);

struct AtomMeasures {
  AtomSet code;
  std::int64_t voxels = 0;
  std::int64_t voxels_in_design = 0;
  std::int64_t voxels_in_core = 0;     // inside the design shrunk by the tolerance
  std::int64_t voxels_beyond_hull = 0; // outside the design grown by the tolerance
  bool thin_feature = false;  // kept so that a feature thinner than twice the tolerance is (planner/atoms/thin_parts.hpp)
  bool thin_gap = false;      // left empty so that a gap narrower than twice the tolerance is
  double volume = 0;                   // mm^3
  double volume_in_design = 0;         // mm^3
  IndexBox bounding_box;
  Vec3 centroid;                       // mm
  AtomClass atom_class = AtomClass::Free;
  bool sliver = false;
};

// The class from the measures and flags above. A sliver is free whatever it holds: the
// zone is a planning band of at least a voxel (plan/planning_band.hpp), where the model's
// slivers are noise of the primitives' edges that a real plan gets within the band (a
// cross of ribs, deposited whole, whose slivers no sequence gets right on the voxels).
AtomClass class_of(const AtomMeasures& m);

// Measures and classifies every atom, thin features and gaps included.
std::vector<AtomMeasures> measure_atoms(const AtomDecomposition& atoms, const Solid& design, const ToleranceZone& zone,
                                        double sliver_threshold_mm3);

}  // namespace hybridctl::planner
