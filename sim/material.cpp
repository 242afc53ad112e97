#include "sim/material.hpp"

#include <algorithm>
#include <bit>
#include <climits>
#include <limits>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "instruments/support_rule.hpp"

namespace hybridctl::sim {
namespace {

using geometry::Index3;
using geometry::IndexBox;

constexpr int kWordBits = geometry::Solid::kWordBits;

int word_of(int x) { return x >> 6; }  // floor division by 64 (arithmetic shift)

// Bits [lo, hi) of a word, 0 <= lo < hi <= 64.
std::uint64_t bit_range(int lo, int hi) {
  const std::uint64_t upper = hi == kWordBits ? ~std::uint64_t{0} : (std::uint64_t{1} << hi) - 1;
  return upper & (~std::uint64_t{0} << lo);
}

// The rows of one move's swept voxels over a box, 64 voxels a word, in scratch storage.
struct RowMask {
  IndexBox box;  // rows y, z; voxels x within
  int w0 = 0, w1 = 0;
  std::vector<std::uint64_t>& words;

  explicit RowMask(std::vector<std::uint64_t>& storage) : words(storage) {}
  bool empty() const { return box.empty(); }
  void reset(const IndexBox& b) {
    box = b;
    if (b.empty()) {
      w0 = w1 = 0;
      words.clear();
      return;
    }
    w0 = word_of(b.lo.x);
    w1 = word_of(b.hi.x - 1) + 1;
    words.assign(std::size_t(w1 - w0) * std::size_t(b.hi.y - b.lo.y) * std::size_t(b.hi.z - b.lo.z), 0);
  }
  // Indexed by absolute word.
  std::uint64_t* row(int y, int z) {
    return words.data() +
           (std::size_t(z - box.lo.z) * std::size_t(box.hi.y - box.lo.y) + std::size_t(y - box.lo.y)) *
               std::size_t(w1 - w0) -
           w0;
  }
  void add(int y, int z, int x0, int x1) {
    x0 = std::max(x0, box.lo.x);
    x1 = std::min(x1, box.hi.x);
    if (x1 <= x0) return;
    std::uint64_t* r = row(y, z);
    const int wa = word_of(x0), wb = word_of(x1 - 1);
    for (int w = wa; w <= wb; ++w) {
      const int lo = w == wa ? x0 - w * kWordBits : 0;
      const int hi = w == wb ? x1 - w * kWordBits : kWordBits;
      r[w] |= bit_range(lo, hi);
    }
  }
};

// Whether row (y, z) of `stock` holds material in some word that voxels [x0, x1) touch.
bool row_has_material(const geometry::Solid& stock, const IndexBox& d, int y, int z, int x0, int x1) {
  if (y < d.lo.y || y >= d.hi.y || z < d.lo.z || z >= d.hi.z) return false;
  const int w0 = std::max(word_of(x0), stock.first_word());
  const int w1 = std::min(word_of(x1 - 1) + 1, stock.first_word() + stock.words_per_row());
  if (w0 >= w1) return false;
  const std::uint64_t* s = stock.row(y, z).data() - stock.first_word();
  std::uint64_t any = 0;
  for (int w = w0; w < w1; ++w) any |= s[w];
  return any != 0;
}

// The sweep of `pieces` along every segment, one job per piece and segment, each with the
// voxels it may sweep within `clip` (empty: unclipped, finite pieces only).
struct SweepJob {
  PieceSweep sweep;
  IndexBox box;
};
std::vector<SweepJob> sweep_jobs(std::span<const ConvexPiece> pieces, std::span<const Segment> segments,
                                 const geometry::Lattice& lattice, const IndexBox& clip) {
  std::vector<SweepJob> jobs;
  jobs.reserve(pieces.size() * segments.size());
  for (const Segment& s : segments)
    for (const ConvexPiece& p : pieces) {
      PieceSweep sweep(p, s, lattice);
      const IndexBox box = sweep.bounds(clip);
      if (!box.empty()) jobs.push_back({sweep, box});
    }
  return jobs;
}

// Calls row(y, z, x0, x1) for every row's swept voxels [x0, x1) of the jobs, within their
// boxes (a row swept by several jobs comes once per job).
// `only_over`, when given: what is swept only ever meets this stock as it is now or with
// less of it (a cut, a collision test), so rows where it holds no material near the sweep
// are skipped instead of computed. Most of a holder's and a nozzle's body sweeps air:
// this is what keeps their tests cheap.
template <class RowFn>
void for_each_swept_row(std::span<const SweepJob> jobs, const geometry::Solid* only_over, RowFn&& row) {
  const IndexBox stored = only_over ? only_over->storage_box() : IndexBox{};
  // A cylinder moved level (a pocket's passes, most of a milling program) or along its
  // axis sweeps the same interval of a row at every height inside its bounds: worked out
  // once per y, on the first height that needs it, instead of once per row.
  std::vector<XRange> per_y;
  std::vector<char> known;
  for (const SweepJob& job : jobs) {
    const IndexBox& b = job.box;
    const bool alike = job.sweep.alike_in_height() && b.hi.z - b.lo.z > 2;
    if (alike) {
      per_y.assign(std::size_t(b.hi.y - b.lo.y), XRange{});
      known.assign(per_y.size(), 0);
    }
    for (int z = b.lo.z; z < b.hi.z; ++z)
      for (int y = b.lo.y; y < b.hi.y; ++y) {
        if (only_over && !row_has_material(*only_over, stored, y, z, b.lo.x, b.hi.x)) continue;
        XRange r;
        if (alike && z > b.lo.z && z < b.hi.z - 1) {
          const std::size_t k = std::size_t(y - b.lo.y);
          if (!known[k]) per_y[k] = job.sweep.row(y, z), known[k] = 1;
          r = per_y[k];
        } else {
          r = job.sweep.row(y, z);
        }
        r.x0 = std::max(r.x0, b.lo.x);
        r.x1 = std::min(r.x1, b.hi.x);
        if (!r.empty()) row(y, z, r.x0, r.x1);
      }
  }
}

// Rasterises the sweep of `pieces` along every segment into `mask` (the union), over the
// swept bounds intersected with `clip` (empty: unclipped, finite pieces only); `only_over`
// as for_each_swept_row's.
void rasterise(RowMask& mask, std::span<const ConvexPiece> pieces, std::span<const Segment> segments,
               const geometry::Lattice& lattice, const IndexBox& clip, const geometry::Solid* only_over = nullptr) {
  const std::vector<SweepJob> jobs = sweep_jobs(pieces, segments, lattice, clip);
  IndexBox all;
  for (const SweepJob& job : jobs) all = all.empty() ? job.box : geometry::box_union(all, job.box);
  mask.reset(all);
  for_each_swept_row(jobs, only_over, [&](int y, int z, int x0, int x1) { mask.add(y, z, x0, x1); });
}

// The part of the domain a sweep over `stock` alone need look at: the box its material
// lies in (`material`, a box holding it), within its storage.
IndexBox over_material(const geometry::Solid& stock, const IndexBox& material) {
  return geometry::box_intersection(stock.storage_box(), material);
}

// The sweep over `stock` alone, for masks only ever intersected with it (a collision
// test): clipped to the box its material lies in and to its rows with material.
void rasterise_over(RowMask& mask, std::span<const ConvexPiece> pieces, std::span<const Segment> segments,
                    const geometry::Solid& stock, const IndexBox& material) {
  const IndexBox clip = over_material(stock, material);
  if (clip.empty())
    mask.reset({});
  else
    rasterise(mask, pieces, segments, stock.lattice(), clip, &stock);
}

// Counts voxels and the box they span.
struct Tally {
  std::int64_t voxels = 0;
  Index3 lo{INT_MAX, INT_MAX, INT_MAX}, hi{INT_MIN, INT_MIN, INT_MIN};

  void add(std::uint64_t bits, int w, int y, int z) {
    if (!bits) return;
    voxels += std::popcount(bits);
    const int xa = w * kWordBits + std::countr_zero(bits), xb = w * kWordBits + 63 - std::countl_zero(bits);
    lo = {std::min(lo.x, xa), std::min(lo.y, y), std::min(lo.z, z)};
    hi = {std::max(hi.x, xb), std::max(hi.y, y), std::max(hi.z, z)};
  }
  geometry::Box3 region(const geometry::Lattice& l) const {
    if (voxels == 0) return {};
    return l.extent({lo, {hi.x + 1, hi.y + 1, hi.z + 1}});
  }
};

// Calls fn(y, z, w, mask_word, stock_word&) for every non-zero mask word inside the
// stock's storage, rows in increasing (or decreasing) z.
template <class Fn>
void for_each_word(RowMask& mask, geometry::Solid& stock, bool z_descending, Fn&& fn) {
  if (mask.empty()) return;
  const IndexBox domain = stock.storage_box();
  const IndexBox rows = geometry::box_intersection(mask.box, domain);
  if (rows.empty()) return;
  const int w0 = std::max(mask.w0, stock.first_word()), w1 = std::min(mask.w1, stock.first_word() + stock.words_per_row());
  for (int i = 0; i < rows.hi.z - rows.lo.z; ++i) {
    const int z = z_descending ? rows.hi.z - 1 - i : rows.lo.z + i;
    for (int y = rows.lo.y; y < rows.hi.y; ++y) {
      const std::uint64_t* m = mask.row(y, z);
      std::uint64_t* s = stock.row(y, z).data() - stock.first_word();
      for (int w = w0; w < w1; ++w)
        if (m[w]) fn(y, z, w, m[w], s[w]);
    }
  }
}

// Lays a bead's swept voxels (`mask`) on the stock by the head's layer rule
// (instruments/support_rule.hpp), applied to the bead as one layer of the build: a column
// of the bead's footprint is held when the rule holds its cell on the material under the
// bead (the plate below the domain, or any material from one voxel layer below the bead's
// bottom up to its middle height, what it fuses with); the new voxels of a column not held
// fell and are counted in `fallen`, not added. The rule's cone and slack are per voxel
// layer, so a bead taller than a voxel is judged at least as leniently as the planner's
// layers judge the same deposit; what matters is caught: beads laid over air.
struct BeadLaying {
  geometry::Solid& stock;
  const IndexBox& domain;
  int plate;  // the first layer above the build plate
  const instruments::SupportRule& rule;
  const geometry::Lattice& lattice;
  std::span<const Segment> axis;  // the bead's axis: the path of the programmed point, mm
  Tally added, overlap, fallen;

  void lay(RowMask& mask) {
    if (mask.empty()) return;
    const IndexBox rows = geometry::box_intersection(mask.box, domain);
    if (rows.empty()) return;
    // Room around the bead for the cone's reach and a bridge's far anchor.
    const int reach = int(std::ceil(rule.reach(1))) + rule.max_bridge_voxels + 1;
    const int gx0 = std::max(domain.lo.x, rows.lo.x - reach), gx1 = std::min(domain.hi.x, rows.hi.x + reach);
    const int gy0 = std::max(domain.lo.y, rows.lo.y - reach), gy1 = std::min(domain.hi.y, rows.hi.y + reach);
    instruments::LayerGrid candidates(gx0, gy0, gx1 - gx0, gy1 - gy0), under(gx0, gy0, gx1 - gx0, gy1 - gy0);
    std::vector<Index3> fresh;  // voxels of the bead not yet material
    for (int z = rows.lo.z; z < rows.hi.z; ++z)
      for (int y = rows.lo.y; y < rows.hi.y; ++y) {
        const std::uint64_t* m = mask.row(y, z);
        for (int w = std::max(mask.w0, word_of(rows.lo.x)); w < mask.w1; ++w)
          for (std::uint64_t bits = m[w]; bits; bits &= bits - 1) {
            const int x = w * kWordBits + std::countr_zero(bits);
            if (x < rows.lo.x || x >= rows.hi.x) continue;
            if (stock.contains({x, y, z})) {
              overlap.add(std::uint64_t{1} << (x - w * kWordBits), w, y, z);
            } else {
              fresh.push_back({x, y, z});
              candidates.set(x, y);
            }
          }
      }
    if (fresh.empty()) return;
    const int bottom = mask.box.lo.z, middle = (mask.box.lo.z + mask.box.hi.z - 1) / 2;
    // The bead is one layer of the build: it looks back one layer, to what it rests on
    // and fuses with; on the plate it needs nothing.
    const bool on_plate = bottom <= plate;
    if (!on_plate)
      for (int y = gy0; y < gy1; ++y)
        for (int x = gx0; x < gx1; ++x)
          for (int z = bottom - 1; z <= middle; ++z)
            if (stock.contains({x, y, z})) {
              under.set(x, y);
              break;
            }
    const instruments::Below below{1, under};
    const instruments::LayerGrid held =
        instruments::supported_cells(candidates, std::span(&below, on_plate ? 0 : 1), under, rule).held;
    // A bead is one melt pool: where its axis is held (by the rule, or resting on material),
    // its whole cross-section is, edges overhanging the layer below included. That is the
    // usual criterion for DED and wire-arc beads (a bead holds while its centre is over
    // what it is laid on and the cone's lean), and it is what makes the planner's voxel
    // layers, whose edge beads spill half a bead beyond, agree with the simulator.
    auto axis_held = [&](int x, int y) {
      const geometry::Vec3 c = lattice.center({x, y, 0});
      double best = std::numeric_limits<double>::infinity();
      geometry::Vec3 at = c;
      for (const Segment& s : axis) {
        const double dx = s.to.x - s.from.x, dy = s.to.y - s.from.y, len2 = dx * dx + dy * dy;
        const double t = len2 > 0 ? std::clamp(((c.x - s.from.x) * dx + (c.y - s.from.y) * dy) / len2, 0.0, 1.0) : 0.0;
        const geometry::Vec3 p{s.from.x + t * dx, s.from.y + t * dy, 0};
        const double d = (p.x - c.x) * (p.x - c.x) + (p.y - c.y) * (p.y - c.y);
        if (d < best) best = d, at = p;
      }
      const int ax = int(std::floor((at.x - lattice.origin.x) / lattice.voxel_size));
      const int ay = int(std::floor((at.y - lattice.origin.y) / lattice.voxel_size));
      return held.filled(ax, ay) || under.filled(ax, ay);
    };
    for (const Index3& v : fresh) {
      const int w = word_of(v.x);
      const std::uint64_t bit = std::uint64_t{1} << (v.x - w * kWordBits);
      if (!held.filled(v.x, v.y) && !axis_held(v.x, v.y)) {
        fallen.add(bit, w, v.y, v.z);
        continue;
      }
      stock.set(v);
      added.add(bit, w, v.y, v.z);
    }
  }
};

}  // namespace

std::string_view to_string(IncidentKind kind) {
  switch (kind) {
    case IncidentKind::RapidIntoMaterial: return "rapid into material";
    case IncidentKind::BodyCollision: return "body collision";
    case IncidentKind::Gouge: return "gouge";
    case IncidentKind::UnsupportedDeposition: return "unsupported deposition";
    case IncidentKind::DepositionOutsideDomain: return "deposition outside the domain";
  }
  return "?";
}

std::string describe(const Incident& i) {
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "line %d: %s: %.6g mm^3 (%lld voxels) in x [%.6g, %.6g] y [%.6g, %.6g] z [%.6g, %.6g], "
                "move (%.6g, %.6g, %.6g) -> (%.6g, %.6g, %.6g)",
                i.line, std::string(to_string(i.kind)).c_str(), i.volume, static_cast<long long>(i.voxels),
                i.region.min.x, i.region.max.x, i.region.min.y, i.region.max.y, i.region.min.z, i.region.max.z,
                i.from.x, i.from.y, i.from.z, i.to.x, i.to.y, i.to.z);
  return buf;
}

MaterialSimulation::MaterialSimulation(geometry::Solid stock, std::optional<geometry::Solid> protected_region,
                                       SimulationOptions options)
    : stock_(std::move(stock)), options_(options) {
  domain_ = stock_.storage_box();
  plate_ = domain_.lo.z;
  empty_ = stock_.empty();
  material_box_ = stock_.bounding_box();
  if (domain_.empty()) throw std::invalid_argument("the stock must have a non-empty storage box (the simulated domain)");
  set_protected_region(std::move(protected_region));
  if (!(options_.arc_tolerance >= 0)) throw std::invalid_argument("arc tolerance must be >= 0");
}

void MaterialSimulation::set_protected_region(std::optional<geometry::Solid> protected_region) {
  if (protected_region && !(protected_region->lattice() == stock_.lattice()))
    throw std::invalid_argument("the protected solid must share the stock's lattice");
  protected_ = std::move(protected_region);
}

double MaterialSimulation::chord_tolerance() const {
  return options_.arc_tolerance > 0 ? options_.arc_tolerance
                                    : std::min(stock_.voxel_size() / 10, SimulationOptions::kDefaultArcTolerance);
}

MoveReport MaterialSimulation::cut(const Cutter& cutter, const MaterialMove& move) {
  const std::vector<Segment> segments = path_segments(move, chord_tolerance());
  const std::vector<ConvexPiece> cutting = pieces_of(cutter.cutting), body = pieces_of(cutter.body);
  const geometry::Lattice& lattice = stock_.lattice();

  const bool rapid = move.motion == Motion::Rapid;
  Tally removed, gouge, contact;
  // The cutting part's sweep is cut from the stock row by row as it is worked out: no
  // mask, and a row another piece of the cutter already cleared is skipped.
  auto remove = [&] {
    const IndexBox clip = over_material(stock_, material_box_);
    if (clip.empty()) return;
    const std::vector<SweepJob> jobs = sweep_jobs(cutting, segments, lattice, clip);
    const int first = stock_.first_word();
    for_each_swept_row(jobs, &stock_, [&](int y, int z, int x0, int x1) {
      std::uint64_t* s = stock_.row(y, z).data() - first;
      const int wa = word_of(x0), wb = word_of(x1 - 1);
      for (int w = wa; w <= wb; ++w) {
        const std::uint64_t m = bit_range(w == wa ? x0 - w * kWordBits : 0, w == wb ? x1 - w * kWordBits : kWordBits);
        const std::uint64_t hit = s[w] & m;
        if (!hit) continue;
        removed.add(hit, w, y, z);
        if (protected_) gouge.add(hit & protected_->word_at(w, y, z), w, y, z);
        if (rapid) contact.add(hit, w, y, z);
        s[w] &= ~m;
      }
    });
  };
  RowMask body_mask(scratch_[1]);
  auto touch = [&] {
    rasterise_over(body_mask, body, segments, stock_, material_box_);
    for_each_word(body_mask, stock_, false,
                  [&](int y, int z, int w, std::uint64_t m, std::uint64_t& s) { contact.add(s & m, w, y, z); });
  };
  // The body sits above the cutting part: it reaches a voxel before the cutter does only
  // when the move rises. On level moves a voxel on their shared boundary is cut.
  if (!rapid && move.to.z > move.from.z) {
    touch();
    remove();
  } else {
    remove();
    touch();
  }

  if (removed.voxels > 0) shrink_material_box({removed.lo, {removed.hi.x + 1, removed.hi.y + 1, removed.hi.z + 1}});
  const double v = stock_.voxel_size() * stock_.voxel_size() * stock_.voxel_size();
  MoveReport out;
  out.removed = double(removed.voxels) * v;
  out.gouge = double(gouge.voxels) * v;
  auto incident = [&](IncidentKind kind, const Tally& t) {
    if (t.voxels == 0) return;
    out.incidents.push_back({kind, move.line, move.from, move.to, double(t.voxels) * v, t.voxels, t.region(lattice)});
  };
  if (rapid) {
    out.rapid_contact = double(contact.voxels) * v;
    incident(IncidentKind::RapidIntoMaterial, contact);
  } else {
    out.collision = double(contact.voxels) * v;
    incident(IncidentKind::BodyCollision, contact);
  }
  incident(IncidentKind::Gouge, gouge);
  finish(move, out);
  return out;
}

void MaterialSimulation::shrink_material_box(const IndexBox& removed) {
  IndexBox& b = material_box_;
  const IndexBox stored = stock_.storage_box();
  // Whether the box's voxels with coordinate `axis` at `at` hold no material.
  auto empty_layer = [&](int axis, int at) {
    if (axis == 2) {
      for (int y = b.lo.y; y < b.hi.y; ++y)
        if (row_has_material(stock_, stored, y, at, b.lo.x, b.hi.x)) return false;
    } else if (axis == 1) {
      for (int z = b.lo.z; z < b.hi.z; ++z)
        if (row_has_material(stock_, stored, at, z, b.lo.x, b.hi.x)) return false;
    } else {
      for (int z = b.lo.z; z < b.hi.z; ++z)
        for (int y = b.lo.y; y < b.hi.y; ++y)
          if (stock_.contains({at, y, z})) return false;
    }
    return true;
  };
  auto lo = [](IndexBox& box, int axis) -> int& { return axis == 0 ? box.lo.x : axis == 1 ? box.lo.y : box.lo.z; };
  auto hi = [](IndexBox& box, int axis) -> int& { return axis == 0 ? box.hi.x : axis == 1 ? box.hi.y : box.hi.z; };
  IndexBox cut = removed;
  for (int axis = 2; axis >= 0 && !b.empty(); --axis) {
    if (lo(cut, axis) <= lo(b, axis))
      while (lo(b, axis) < hi(b, axis) && empty_layer(axis, lo(b, axis))) ++lo(b, axis);
    if (hi(cut, axis) >= hi(b, axis))
      while (hi(b, axis) > lo(b, axis) && empty_layer(axis, hi(b, axis) - 1)) --hi(b, axis);
  }
  if (b.empty()) b = {};
}

MoveReport MaterialSimulation::deposit(const Bead& bead, const MaterialMove& move) {
  const std::vector<Segment> segments = path_segments(move, chord_tolerance());
  const std::vector<ConvexPiece> shape = pieces_of(bead), body = pieces_of(bead.body);
  const geometry::Lattice& lattice = stock_.lattice();
  const double v = stock_.voxel_size() * stock_.voxel_size() * stock_.voxel_size();
  const bool rapid = move.motion == Motion::Rapid;
  MoveReport out;
  auto incident = [&](IncidentKind kind, const Tally& t) {
    if (t.voxels == 0) return;
    out.incidents.push_back({kind, move.line, move.from, move.to, double(t.voxels) * v, t.voxels, t.region(lattice)});
  };
  Tally contact;
  auto touch = [&](RowMask& mask) {
    for_each_word(mask, stock_, false,
                  [&](int y, int z, int w, std::uint64_t m, std::uint64_t& s) { contact.add(s & m, w, y, z); });
  };

  if (move.process_on) {
    RowMask bead_mask(scratch_[0]), body_mask(scratch_[1]);
    rasterise(bead_mask, shape, segments, lattice, {});
    // Bead voxels beyond the domain are lost.
    Tally outside;
    if (!bead_mask.empty()) {
      const int dw0 = stock_.first_word(), dw1 = dw0 + stock_.words_per_row();
      for (int z = bead_mask.box.lo.z; z < bead_mask.box.hi.z; ++z)
        for (int y = bead_mask.box.lo.y; y < bead_mask.box.hi.y; ++y) {
          const bool row_inside = y >= domain_.lo.y && y < domain_.hi.y && z >= domain_.lo.z && z < domain_.hi.z;
          const std::uint64_t* m = bead_mask.row(y, z);
          for (int w = bead_mask.w0; w < bead_mask.w1; ++w)
            if (!row_inside || w < dw0 || w >= dw1) outside.add(m[w], w, y, z);
        }
    }
    const instruments::SupportRule rule = instruments::support_rule(bead.support, stock_.voxel_size());
    // Nothing there yet: the program builds from a plate, whose top is where it lays its
    // first bead (a plan that starts by depositing starts at the design's lowest layer).
    if (empty_ && !bead_mask.empty()) plate_ = std::max(plate_, bead_mask.box.lo.z);
    BeadLaying laying{stock_, domain_, plate_, rule, lattice, segments, {}, {}, {}};
    // The body sits above the bead: fresh material can reach it only on a falling move.
    // The body's mask is made over the stock as the body meets it (only_over).
    if (move.to.z < move.from.z) {
      laying.lay(bead_mask);
      rasterise_over(body_mask, body, segments, stock_, material_box_);
      touch(body_mask);
    } else {
      rasterise_over(body_mask, body, segments, stock_, material_box_);
      touch(body_mask);
      laying.lay(bead_mask);
    }
    const Tally& added = laying.added;
    const Tally& overlap = laying.overlap;
    if (added.voxels > 0) {
      empty_ = false;
      const IndexBox grown{added.lo, {added.hi.x + 1, added.hi.y + 1, added.hi.z + 1}};
      material_box_ = material_box_.empty() ? grown : geometry::box_union(material_box_, grown);
    }
    out.deposited = double(added.voxels) * v;
    out.overlap = double(overlap.voxels) * v;
    out.outside = double(outside.voxels) * v;
    if (rapid) {
      out.rapid_contact = double(contact.voxels) * v;
      incident(IncidentKind::RapidIntoMaterial, contact);
    } else {
      out.collision = double(contact.voxels) * v;
      incident(IncidentKind::BodyCollision, contact);
    }
    incident(IncidentKind::UnsupportedDeposition, laying.fallen);
    incident(IncidentKind::DepositionOutsideDomain, outside);
  } else {
    // Travel: a rapid must keep bead and body out of material, a feed move the body.
    RowMask mask(scratch_[0]);
    std::vector<ConvexPiece> pieces = body;
    if (rapid) pieces.insert(pieces.end(), shape.begin(), shape.end());
    rasterise_over(mask, pieces, segments, stock_, material_box_);
    touch(mask);
    if (rapid) {
      out.rapid_contact = double(contact.voxels) * v;
      incident(IncidentKind::RapidIntoMaterial, contact);
    } else {
      out.collision = double(contact.voxels) * v;
      incident(IncidentKind::BodyCollision, contact);
    }
  }
  finish(move, out);
  return out;
}

void MaterialSimulation::finish(const MaterialMove&, MoveReport& out) {
  ++report_.moves;
  report_.removed += out.removed;
  report_.gouge += out.gouge;
  report_.deposited += out.deposited;
  report_.overlap += out.overlap;
  report_.outside += out.outside;
  report_.collision += out.collision;
  report_.rapid_contact += out.rapid_contact;
  report_.incidents.insert(report_.incidents.end(), out.incidents.begin(), out.incidents.end());
}

}  // namespace hybridctl::sim
