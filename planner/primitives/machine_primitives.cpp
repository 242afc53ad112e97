#include "planner/primitives/machine_primitives.hpp"

#include <array>
#include <deque>

#include <tbb/parallel_for.h>

#include "geometry/shapes.hpp"
#include "instruments/bead.hpp"
#include "instruments/cutter.hpp"
#include "instruments/elements.hpp"
#include "planner/primitives/shapes.hpp"
#include "planner/primitives/support.hpp"

namespace hybridctl::planner {
namespace {

using geometry::Solid;

std::string setup_words(const config::Setup& s) {
  return "from " + std::string(config::to_string(s.approach)) + " (" + s.name + ")";
}

}  // namespace


// Deposition builds layer on layer from below the nozzle: the nozzle body constrains
// the toolpath's clearance moves, not the depositable shape (ARCHITECTURE.md).
Instrument bead_instrument(const config::AdditiveHead& head, config::Approach approach) {
  Instrument in;
  in.cutting.push_back(instruments::bead_element(instruments::bead_of(head), approach));
  return in;
}

// The cutter and its body (shank, then the holder, which never ends: whatever lies in its
// shadow is out of reach), from the tip towards the approach side.
Instrument tool_instrument(const config::CuttingTool& tool, config::Approach approach) {
  const instruments::Cutter cutter = instruments::cutter_of(tool);
  Instrument in;
  in.cutting.push_back(instruments::axial_body(cutter.cutting, approach));
  in.body.push_back(instruments::axial_body(cutter.body, approach));
  return in;
}

std::size_t machine_primitive_count(const config::Machine& m) {
  std::size_t total = m.raw_stocks.size();
  for (const auto& head : m.heads) total += m.setups.size() * head.primitives.size();
  for (const auto& tool : m.tools) total += m.setups.size() * tool.primitives.size();
  return total;
}

geometry::Box3 stock_bounds(const config::RawStock& s, const geometry::Box3& d) {
  const std::array<double, 3>& m = s.margin;
  switch (s.kind) {
    case config::RawStock::Kind::Box:
      return {{d.min.x - m[0], d.min.y - m[1], d.min.z - m[2]}, {d.max.x + m[0], d.max.y + m[1], d.max.z + m[2]}};
    case config::RawStock::Kind::Plate:
      return {{d.min.x - m[0], d.min.y - m[1], d.min.z}, {d.max.x + m[0], d.max.y + m[1], d.min.z + s.plate_thickness}};
    case config::RawStock::Kind::RoundBar: break;
  }
  const geometry::Vec3 c{(d.min.x + d.max.x) / 2, (d.min.y + d.max.y) / 2, (d.min.z + d.max.z) / 2};
  const double r = s.bar_diameter / 2, l = s.bar_length / 2;
  const geometry::Vec3 half{s.bar_axis == config::Axis::X ? l : r, s.bar_axis == config::Axis::Y ? l : r,
                            s.bar_axis == config::Axis::Z ? l : r};
  return {{c.x - half.x, c.y - half.y, c.z - half.z}, {c.x + half.x, c.y + half.y, c.z + half.z}};
}

namespace {

// The deposits per head and setup (U-AM, O-AM), unnamed, made in parallel: each one's cut
// to what builds layer by layer (planner/primitives/support.hpp) is one sequential pass over its layers.
std::vector<Primitive> deposit_primitives(const config::Machine& m, const Solid& design, const Solid* present) {
  struct Deposit {
    Primitive p;
    const config::AdditiveHead* head;
    const config::Setup* setup;
  };
  std::vector<Deposit> deposits;
  for (const auto& head : m.heads)
    for (const auto& setup : m.setups)
      for (const auto kind : head.primitives) {
        Primitive p;
        p.mode = Mode::Additive;
        p.capability = head.name;
        p.setup = setup.name;
        p.cost_per_mm3 = head.cost_per_mm3;
        if (kind == config::PrimitiveKind::UAm) {
          p.kind = PrimitiveKind::UAm;
          p.label = "U-AM " + head.name + " " + setup_words(setup);
        } else if (kind == config::PrimitiveKind::OAm) {
          p.kind = PrimitiveKind::OAm;
          p.label = "O-AM " + head.name + " " + setup_words(setup);
        } else {
          continue;
        }
        deposits.push_back({std::move(p), &head, &setup});
      }
  tbb::parallel_for(std::size_t(0), deposits.size(), [&](std::size_t k) {
    Deposit& d = deposits[k];
    Instrument in = bead_instrument(*d.head, d.setup->approach);
    // The overfill covers the design by a bead and by the machining allowance, the stock a
    // finishing removal takes off (the face rule holds it to being finished).
    if (d.p.kind == PrimitiveKind::OAm && d.head->machining_allowance > 0)
      in.cutting.push_back(geometry::Ball{d.head->machining_allowance});
    const Solid region = d.p.kind == PrimitiveKind::UAm ? additive_maximal(design, in) : additive_conservative(design, in);
    // Only what the head builds without support in this setup.
    d.p.region = self_supporting(region, instruments::approach_direction(d.setup->approach),
                                 instruments::support_rule(d.head->support, design.voxel_size()), present);
  });
  std::vector<Primitive> out;
  for (Deposit& d : deposits) out.push_back(std::move(d.p));
  return out;
}

bool machine_has_deposits(const config::Machine& m) {
  for (const auto& head : m.heads)
    if (!head.primitives.empty() && !m.setups.empty()) return true;
  return false;
}

}  // namespace

std::vector<Primitive> machine_primitives(const config::Machine& m, const Solid& design,
                                          const geometry::IndexBox& domain, const PrimitiveProgress& progress,
                                          const Solid* present) {
  std::vector<Primitive> out;
  const geometry::Lattice& lattice = design.lattice();
  const geometry::Box3 bb = design.bounding_box_mm();
  const std::size_t total = machine_primitive_count(m);
  auto add = [&](Primitive p, const std::function<Solid()>& make) {
    if (progress) progress(out.size(), total, p.label);
    p.region = make();
    p.name = primitive_name(out.size());
    out.push_back(std::move(p));
  };

  for (const auto& stock : m.raw_stocks) {
    Primitive p;
    p.kind = PrimitiveKind::RawStock;
    p.mode = Mode::Additive;
    p.capability = stock.name;
    p.cost_per_mm3 = 0;  // material is not costed; removing it is
    if (stock.kind != config::RawStock::Kind::RoundBar) {
      p.label = "raw stock " + stock.name + (stock.kind == config::RawStock::Kind::Box ? " (box)" : " (plate)");
      add(p, [&] { return geometry::make_box(lattice, stock_bounds(stock, bb)); });
    } else {
      p.label = "raw stock " + stock.name + " (round bar)";
      add(p, [&] {
        const geometry::Vec3 c{(bb.min.x + bb.max.x) / 2, (bb.min.y + bb.max.y) / 2, (bb.min.z + bb.max.z) / 2};
        const geometry::Axis axis = stock.bar_axis == config::Axis::X   ? geometry::Axis::X
                                    : stock.bar_axis == config::Axis::Y ? geometry::Axis::Y
                                                                        : geometry::Axis::Z;
        geometry::Vec3 base = c;
        (axis == geometry::Axis::X ? base.x : axis == geometry::Axis::Y ? base.y : base.z) -= stock.bar_length / 2;
        return geometry::make_cylinder(lattice, axis, base, stock.bar_diameter / 2, stock.bar_length);
      });
    }
  }

  if (progress && machine_has_deposits(m)) progress(out.size(), total, "deposits");
  for (Primitive& p : deposit_primitives(m, design, present)) {
    Solid region = std::move(p.region);
    add(std::move(p), [&] { return std::move(region); });
  }

  // Removal regions are computed together: tools from the same side share the design's
  // distance transforms (primitive_shapes.hpp, removal_regions).
  std::deque<Instrument> instruments;
  std::vector<Primitive> removals;
  std::vector<RemovalRequest> requests;
  for (const auto& tool : m.tools)
    for (const auto& setup : m.setups) {
      const Instrument* in = &instruments.emplace_back(tool_instrument(tool, setup.approach));
      for (const auto kind : tool.primitives) {
        Primitive p;
        p.mode = Mode::Subtractive;
        p.capability = "T" + std::to_string(tool.number);
        p.tool_number = tool.number;
        p.setup = setup.name;
        p.cost_per_mm3 = tool.cost_per_mm3;
        const std::string tool_words = "T" + std::to_string(tool.number) + " (" + tool.name + ") " + setup_words(setup);
        if (kind == config::PrimitiveKind::SmMax) {
          p.kind = PrimitiveKind::SmMax;
          p.label = "SM-max " + tool_words;
        } else if (kind == config::PrimitiveKind::SmCons) {
          p.kind = PrimitiveKind::SmCons;
          p.label = "SM-cons " + tool_words;
        } else {
          continue;
        }
        removals.push_back(std::move(p));
        requests.push_back({in, kind == config::PrimitiveKind::SmMax});
      }
    }
  if (!requests.empty()) {
    if (progress) progress(out.size(), total, removals.front().label);
    const std::size_t before = out.size();
    std::vector<Solid> regions = removal_regions(design, requests, domain, [&](std::size_t i) {
      if (progress) progress(before + i + 1, total, i + 1 < removals.size() ? removals[i + 1].label : "done");
    });
    for (std::size_t i = 0; i < removals.size(); ++i) {
      removals[i].region = std::move(regions[i]);
      removals[i].name = primitive_name(out.size());
      out.push_back(std::move(removals[i]));
    }
  }
  if (progress) progress(out.size(), total, "done");
  return out;
}

std::string primitive_name(std::size_t index) { return "P" + std::to_string(index + 1); }

}  // namespace hybridctl::planner
