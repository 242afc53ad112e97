#include "report/report_atoms.hpp"

#include <algorithm>
#include <cstdint>
#include <unordered_map>

#include "common/error.hpp"

namespace hybridctl::report {
namespace {

using geometry::Index3;
using geometry::Solid;

int floor_div(int a, int b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

// A membership code as bytes: bit p of the key says whether the voxel is in P(p+1).
std::string code_key(const std::string& code) {
  std::string key((code.size() + 7) / 8, '\0');
  for (std::size_t p = 0; p < code.size(); ++p)
    if (code[p] == '1') key[p / 8] = char(key[p / 8] | (1 << (p % 8)));
  return key;
}

}  // namespace

AtomSolids atom_solids(const plan::PlanFile& file, const std::vector<std::string>& codes,
                       const std::vector<std::string>& classes, const std::vector<int>& violating) {
  const std::size_t n = file.primitives.size();
  std::unordered_map<std::string, int> atom_of;
  for (std::size_t a = 0; a < codes.size(); ++a) {
    if (codes[a].size() != n)
      throw InputError(file.directory.string() + "/plan.json: atoms[" + std::to_string(a) + "].code has " +
                       std::to_string(codes[a].size()) + " characters, expected one per primitive (" +
                       std::to_string(n) + ")");
    atom_of.emplace(code_key(codes[a]), int(a));
  }
  std::vector<int> slot(codes.size(), -1);  // -1: by class; else index into violating
  AtomSolids out{Solid(file.lattice, file.domain), Solid(file.lattice, file.domain), Solid(file.lattice, file.domain),
                 violating, {}};
  for (std::size_t i = 0; i < violating.size(); ++i) {
    if (violating[i] >= 0 && std::size_t(violating[i]) < slot.size()) slot[violating[i]] = int(i);
    out.violating.emplace_back(file.lattice, file.domain);
  }
  // Voxel by voxel only where some primitive's boundary crosses a 64-voxel word; a word
  // that every primitive holds wholly or not at all is one atom, set as a run.
  const geometry::IndexBox& d = file.domain;
  std::string key((n + 7) / 8, '\0');
  std::vector<std::uint64_t> words(n);
  auto target = [&](int a) -> Solid* {
    if (slot[a] >= 0) return &out.violating[slot[a]];
    const std::string& cls = a < int(classes.size()) ? classes[a] : std::string();
    return cls == "must-in" ? &out.must_in : cls == "must-out" ? &out.must_out : cls == "free" ? &out.free : nullptr;
  };
  auto atom_at = [&](int bit) {
    std::fill(key.begin(), key.end(), '\0');
    for (std::size_t p = 0; p < n; ++p)
      if ((words[p] >> bit) & 1) key[p / 8] = char(key[p / 8] | (1 << (p % 8)));
    const auto it = atom_of.find(key);
    return it == atom_of.end() ? -1 : it->second;  // -1: not an atom plan.json lists
  };
  const int w_lo = floor_div(d.lo.x, 64), w_hi = floor_div(d.hi.x - 1, 64);
  for (int z = d.lo.z; z < d.hi.z; ++z)
    for (int y = d.lo.y; y < d.hi.y; ++y)
      for (int w = w_lo; w <= w_hi; ++w) {
        const int x0 = std::max(d.lo.x, w * 64), x1 = std::min(d.hi.x, w * 64 + 64);
        bool uniform = true;
        for (std::size_t p = 0; p < n; ++p) {
          words[p] = file.primitives[p].region.word_at(w, y, z);
          uniform = uniform && (words[p] == 0 || words[p] == ~std::uint64_t(0));
        }
        if (uniform) {
          const int a = atom_at(0);
          if (Solid* s = a >= 0 ? target(a) : nullptr) s->set_run(y, z, x0, x1);
          continue;
        }
        for (int x = x0; x < x1; ++x) {
          const int a = atom_at(x - w * 64);
          if (Solid* s = a >= 0 ? target(a) : nullptr) s->set({x, y, z});
        }
      }
  return out;
}

}  // namespace hybridctl::report
