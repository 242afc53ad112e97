#pragma once
// The primitives a machine offers for a design: for every additive head x setup its
// U-AM and O-AM, for every cutting tool x setup its SM-max and SM-cons (as the machine
// file allows), and the raw stocks. Primitives given as files join them.

#include <functional>
#include <string>
#include <vector>

#include "config/machine.hpp"
#include "geometry/morphology.hpp"
#include "geometry/solid.hpp"
#include "planner/primitives/shapes.hpp"
#include "planner/problem/problem.hpp"

namespace hybridctl::planner {

using config::PrimitiveKind;

struct Primitive {
  std::string name;          // P1, P2, ... in order
  std::string label;         // for people: "U-AM DED-1 from +Z (top)"
  PrimitiveKind kind = PrimitiveKind::File;
  Mode mode = Mode::Additive;
  std::string capability;    // head name, "T<n>", stock name or file path
  std::string setup;         // setup name; empty for stocks and files
  int tool_number = 0;       // for cutting tools
  double cost_per_mm3 = 0;
  geometry::Solid region;    // deposited (additive) or removed (subtractive) region
  bool from_file = false;    // a raw stock given as a file: `capability` is its path
};

// The structuring elements of a head's bead and of a tool's cutting part and body, in
// the part frame of a setup (the body extends from the tip towards the approach side):
// the shapes instruments/ defines (bead_of, cutter_of), laid along the approach.
Instrument bead_instrument(const config::AdditiveHead& head, config::Approach approach);
Instrument tool_instrument(const config::CuttingTool& tool, config::Approach approach);

// The name of the primitive at `index` of a planning job's list, as the paper and plan.json
// write it: P1 for the first. The one place primitives are named.
std::string primitive_name(std::size_t index);

// Called with a message before each primitive is computed.
using PrimitiveProgress = std::function<void(std::size_t done, std::size_t total, const std::string& what)>;

// Where a raw stock sits against a design's bounding box (mm): a box grown by its margins,
// a plate from the design's lowest face up by its thickness and out by its margins on X
// and Y, a round bar's bounding box (centred on the design's, along its axis).
geometry::Box3 stock_bounds(const config::RawStock& stock, const geometry::Box3& design);

// How many primitives machine_primitives returns: every raw stock, and every head's and
// tool's primitive kinds over the setups.
std::size_t machine_primitive_count(const config::Machine& machine);

// Stocks first, then heads, then tools, each over the machine's setups. `present`, when
// given, is the stock every plan starts from: deposits are cut to what builds on the plate
// or on it (planner/primitives/support.hpp).
std::vector<Primitive> machine_primitives(const config::Machine& machine, const geometry::Solid& design,
                                          const geometry::IndexBox& domain, const PrimitiveProgress& progress = {},
                                          const geometry::Solid* present = nullptr);

}  // namespace hybridctl::planner
