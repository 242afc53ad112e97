#pragma once
// The layer rule: what a head builds without support, on voxels. The one definition the
// planner's additive primitives (planner/primitives/support.hpp) and the simulator's deposition
// (sim/material.cpp) both apply, from the head's `support` keys (config::SupportLimits).
// docs/support.md explains the model with figures.
//
// Layers are one voxel thick, stacked along the build direction. A voxel of a new layer
// is held
//  - in the cone: for each look-back n (1, 2, 4, 8 and 16 layers, and the build's first
//    layer when it is nearer than 16), material n layers below lies within a horizontal
//    distance of n tan(a) + 1 voxels, a the head's max_overhang; a look-back that would
//    pass the first layer finds the plate, which is everywhere. One layer up a wall may
//    lean out by tan(a); the one voxel of slack absorbs the staircase of a voxelized wall
//    (each layer's edge is within half a voxel of the true wall, along the axes and the
//    diagonals alike), and looking back many layers keeps the slack from adding up, so a
//    wall steeper than the cone is cut where it has leaned a voxel beyond it;
//  - or bridged: it lies on a run of voxels along X or Y, none held by the cone, held at
//    both ends by held voxels or material of the same layer, and the run is at most
//    max_bridge long. Runs along X are found first; a voxel bridged along X may hold a
//    run along Y. A bridge is a new footing: the layers above look back to it, not past it.
// Everything else would be laid over air: it falls.

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "config/machine.hpp"

namespace hybridctl::instruments {

struct SupportRule {
  double lean_per_layer = 0;  // tan(max_overhang): voxels a wall may lean out per layer
  int max_bridge_voxels = 0;  // longest run over air, in voxels; 0: none
  static constexpr double kSlack = 1.0;                       // voxels
  static constexpr std::array<int, 5> kLookBack = {1, 2, 4, 8, 16};  // layers

  // How far (voxels) material `layers` below may lie from a voxel it holds.
  double reach(int layers) const { return layers * lean_per_layer + kSlack; }
};

// The rule of a head's limits on a lattice of voxel size `voxel_size` (mm, > 0).
SupportRule support_rule(const config::SupportLimits& limits, double voxel_size);

// One layer as a dense grid of cells [x0, x0 + nx) x [y0, y0 + ny); cells outside are empty.
struct LayerGrid {
  int x0 = 0, y0 = 0, nx = 0, ny = 0;
  std::vector<std::uint8_t> cells;

  LayerGrid() = default;
  LayerGrid(int x0_, int y0_, int nx_, int ny_)
      : x0(x0_), y0(y0_), nx(nx_), ny(ny_), cells(std::size_t(nx_) * std::size_t(ny_), 0) {}
  bool inside(int x, int y) const { return x >= x0 && x < x0 + nx && y >= y0 && y < y0 + ny; }
  bool filled(int x, int y) const { return inside(x, y) && cells[index(x, y)] != 0; }
  void set(int x, int y) { cells[index(x, y)] = 1; }
  std::size_t index(int x, int y) const { return std::size_t(y - y0) * std::size_t(nx) + std::size_t(x - x0); }
};

// The material some layers under the candidates.
struct Below {
  int layers = 1;
  LayerGrid material;
};
// The look-backs of a layer `built` layers above the build's first (0: the first layer,
// on the plate: none): SupportRule::kLookBack up to `built`, and `built` itself.
std::vector<int> look_backs(int built);

struct HeldCells {
  LayerGrid held;     // the candidates the rule holds (cone or bridge)
  LayerGrid bridged;  // of which held by a bridge only
};

// The cells of `candidates` (voxels about to be laid) the rule holds. `below`: the
// material of each look-back, with what bridges of the layers between hold (a bridge is a
// footing); none when the candidates lie on the plate. `present`: material already in the
// candidates' layer, which may hold a bridge's ends. Every grid has the candidates' box.
HeldCells supported_cells(const LayerGrid& candidates, std::span<const Below> below, const LayerGrid& present,
                          const SupportRule& rule);

}  // namespace hybridctl::instruments
