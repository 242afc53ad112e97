// The machine's hardware sections: the envelope (linear and rotary axes), the additive
// heads (bead, layer height and hatch spacing against the bead, deposition codes, T
// numbers) and the cutting tools (corner radius by type, step-down and step-over against
// the flutes, stick-out against the Z travel).

#include <algorithm>
#include <cmath>

#include "config/machine_reader.hpp"

namespace hybridctl::config::detail {

namespace {

constexpr long kMaxToolNumber = 99999;

const std::vector<std::pair<std::string_view, DepositionProcess>> kProcesses = {
    {"ded-powder", DepositionProcess::DedPowder},
    {"ded-wire", DepositionProcess::DedWire},
    {"wire-arc", DepositionProcess::WireArc},
    {"laser-wire", DepositionProcess::LaserWire}};
const std::vector<std::pair<std::string_view, BeadShape>> kBeadShapes = {{"ellipsoid", BeadShape::Ellipsoid},
                                                                         {"cylinder", BeadShape::Cylinder}};
const std::vector<std::pair<std::string_view, ToolType>> kToolTypes = {
    {"flat", ToolType::Flat}, {"ball", ToolType::Ball}, {"bull", ToolType::Bull}};
const std::vector<std::pair<std::string_view, PrimitiveKind>> kAdditivePrimitives = {{"u-am", PrimitiveKind::UAm},
                                                                                    {"o-am", PrimitiveKind::OAm}};
const std::vector<std::pair<std::string_view, PrimitiveKind>> kSubtractivePrimitives = {
    {"sm-max", PrimitiveKind::SmMax}, {"sm-cons", PrimitiveKind::SmCons}};

}  // namespace

// ------------------------------------------------------------ envelope

void MachineReader::read_envelope(const Value& v) {
  MapReader r(sink_, v, {"X", "Y", "Z", "A", "B", "C"});
  if (!r.ok()) return;
  const std::size_t before = sink_.count();
  if (auto f = r.require("X")) read_linear_axis(f->value, machine_.envelope.x);
  if (auto f = r.require("Y")) read_linear_axis(f->value, machine_.envelope.y);
  if (auto f = r.require("Z")) z_travel_known_ = read_linear_axis(f->value, machine_.envelope.z);
  for (char name : {'A', 'B', 'C'})
    if (auto f = r.find(std::string(1, name))) read_rotary_axis(f->value, name);
  rotary_axes_known_ = sink_.count() == before;
}

bool MachineReader::read_linear_axis(const Value& v, LinearAxis& axis) {
  MapReader r(sink_, v, {"travel", "max_feed", "max_acceleration"});
  if (!r.ok()) return false;
  bool travel_read = false;
  if (auto f = r.require("travel")) {
    const auto travel = read_range(sink_, f->value, kLength);
    set(travel, axis.travel);
    travel_read = travel.has_value();
  }
  number(r, "max_feed", kFeed, Bound::Positive, axis.max_feed);
  number(r, "max_acceleration", kAcceleration, Bound::Positive, axis.max_acceleration);
  return travel_read;
}

void MachineReader::read_rotary_axis(const Value& v, char name) {
  MapReader r(sink_, v, {"range", "max_feed", "max_acceleration"});
  if (!r.ok()) return;
  RotaryAxis axis;
  axis.name = name;
  if (auto f = r.require("range")) set(read_range(sink_, f->value, kAngle), axis.range);
  number(r, "max_feed", kAngularFeed, Bound::Positive, axis.max_feed);
  number(r, "max_acceleration", kAngularAcceleration, Bound::Positive, axis.max_acceleration);
  machine_.envelope.rotary.push_back(axis);
}

// ------------------------------------------------------------ additive heads

std::optional<std::size_t> MachineReader::read_heads(const Value& v) {
  const auto items = read_list(sink_, v, "additive heads");
  if (!items) return std::nullopt;
  for (const auto& item : *items) read_head(item);
  return items->size();
}

void MachineReader::read_head(const Value& v) {
  MapReader r(sink_, v,
              {"name", "process", "bead", "nozzle", "support", "layer_height", "hatch_spacing", "travel_clearance",
               "accuracy", "machining_allowance", "feed", "tool_number", "codes", "cost_per_mm3", "deposition_rate",
               "material", "primitives"});
  if (!r.ok()) return;
  AdditiveHead h;
  if (auto f = r.require("name")) {
    set(read_string(sink_, f->value, "a head name"), h.name);
    if (!h.name.empty()) unique(head_names_, h.name, f->value, "head name");
  }
  if (auto f = r.require("process")) set(read_enum(sink_, f->value, kProcesses), h.process);

  bool bead_known = false;
  if (auto f = r.require("bead")) {
    MapReader b(sink_, f->value, {"shape", "width", "height"});
    if (b.ok()) {
      if (auto s = b.find("shape")) set(read_enum(sink_, s->value, kBeadShapes), h.bead.shape);
      const auto width = required_length(b, "width", h.bead.width);
      const auto height = required_length(b, "height", h.bead.height);
      bead_known = width && height;
    }
  }
  if (auto f = r.find("nozzle")) read_nozzle(f->value, h, bead_known);
  h.support = default_support(h.process);
  if (auto f = r.find("support")) read_support(f->value, h.support);

  // Layer height and hatch spacing default to fractions of the bead and may not exceed it.
  if (auto f = r.find("layer_height")) {
    if (auto lh = read_number(sink_, f->value, kLength, Bound::Positive)) {
      if (bead_known && *lh > h.bead.height)
        sink_.error(f->value.mark, f->value.path + ": expected at most the bead height " + fmt(h.bead.height) +
                                       " mm, got " + describe(f->value.node));
      h.layer_height = *lh;
    }
  } else {
    h.layer_height = kDefaultLayerHeightFraction * h.bead.height;
  }
  if (auto f = r.find("hatch_spacing")) {
    if (auto hs = read_number(sink_, f->value, kLength, Bound::Positive)) {
      if (bead_known && *hs > h.bead.width)
        sink_.error(f->value.mark, f->value.path + ": expected at most the bead width " + fmt(h.bead.width) +
                                       " mm, got " + describe(f->value.node));
      h.hatch_spacing = *hs;
    }
  } else {
    h.hatch_spacing = kDefaultHatchSpacingFraction * h.bead.width;
  }

  number(r, "travel_clearance", kLength, Bound::NonNegative, h.travel_clearance);
  h.accuracy = default_accuracy(h.process);
  number(r, "accuracy", kLength, Bound::Positive, h.accuracy);
  h.machining_allowance = default_machining_allowance(h.process);
  number(r, "machining_allowance", kLength, Bound::NonNegative, h.machining_allowance);
  number(r, "feed", kFeed, Bound::Positive, h.feed);
  // The T number: given, or 100 + the head's index; clashes are checked once tools are read.
  h.tool_number = kDefaultHeadToolNumberBase + static_cast<int>(machine_.heads.size());
  HeadToolNumber place{v.mark, v.path + ".tool_number", false};
  if (auto f = r.find("tool_number")) {
    place = {f->value.mark, f->value.path, true};
    set(read_integer(sink_, f->value, 1, kMaxToolNumber,
                     "a positive integer tool number (1.." + std::to_string(kMaxToolNumber) + ")"),
        h.tool_number);
  }
  head_tool_numbers_.push_back(place);
  number(r, "cost_per_mm3", kCostFactor, Bound::NonNegative, h.cost_per_mm3);
  number(r, "deposition_rate", kVolumeRate, Bound::Positive, h.deposition_rate);
  h.material = default_material(h.process);
  if (auto f = r.find("material")) read_material(f->value, h.material);
  if (auto f = r.find("codes")) read_deposition_codes(f->value, h.codes);
  if (auto f = r.find("primitives")) h.primitives = primitives(f->value, kAdditivePrimitives, h.primitives);
  machine_.heads.push_back(std::move(h));
}

// What the head's deposit is made of (docs/costs.md): the process's defaults, key by key.
void MachineReader::read_material(const Value& v, DepositMaterial& m) {
  MapReader r(sink_, v, {"density", "price_per_kg", "efficiency"});
  if (!r.ok()) return;
  number(r, "density", kDensity, Bound::Positive, m.density);
  number(r, "price_per_kg", kPricePerKg, Bound::NonNegative, m.price_per_kg);
  if (auto f = r.find("efficiency")) {
    const auto e = read_number(sink_, f->value, kFraction, Bound::Positive);
    if (e && *e > 1)
      sink_.error(f->value.mark, f->value.path + ": expected a fraction of the material fed, 0 < e <= 1, got " +
                                     describe(f->value.node));
    else
      set(e, m.efficiency);
  }
}

// The nozzle body: its tip stands `standoff` above the programmed point and must clear the
// bead the head lays (docs/support.md, "The nozzle").
void MachineReader::read_nozzle(const Value& v, AdditiveHead& h, bool bead_known) {
  MapReader n(sink_, v, {"diameter", "length", "standoff"});
  if (!n.ok()) return;
  Nozzle nozzle;
  nozzle.standoff = default_standoff(h.process);
  const auto d = required_length(n, "diameter", nozzle.diameter);
  const auto l = required_length(n, "length", nozzle.length);
  bool standoff_ok = true;
  if (auto f = n.find("standoff")) {
    const auto s = read_number(sink_, f->value, kLength, Bound::Positive);
    standoff_ok = s.has_value();
    if (s) nozzle.standoff = *s;
    if (s && bead_known && *s <= h.bead.height) {
      sink_.error(f->value.mark, f->value.path + ": expected more than the bead height " + fmt(h.bead.height) +
                                     " mm (the nozzle tip must clear the bead it lays), got " + describe(f->value.node));
      standoff_ok = false;
    }
  } else if (bead_known && nozzle.standoff <= h.bead.height) {
    sink_.error(v.mark, v.path + ": the default standoff " + fmt(nozzle.standoff) + " mm of " +
                            std::string(to_string(h.process)) + " does not clear the bead height " +
                            fmt(h.bead.height) + " mm; expected a 'standoff' above it");
    standoff_ok = false;
  }
  if (d && l && standoff_ok) h.nozzle = nozzle;
}

// What the head builds without support; keys not given keep the process's defaults.
void MachineReader::read_support(const Value& v, SupportLimits& support) {
  MapReader r(sink_, v, {"max_overhang", "max_bridge"});
  if (!r.ok()) return;
  if (auto f = r.find("max_overhang")) {
    if (auto a = read_number(sink_, f->value, kAngle, Bound::NonNegative)) {
      if (*a >= 90)
        sink_.error(f->value.mark, f->value.path +
                                       ": expected an angle from the build direction below 90 degrees (90 would be a "
                                       "horizontal shelf over air), got " + describe(f->value.node));
      else
        support.max_overhang = *a;
    }
  }
  number(r, "max_bridge", kLength, Bound::NonNegative, support.max_bridge);
}

void MachineReader::read_deposition_codes(const Value& v, DepositionCodes& codes) {
  MapReader r(sink_, v, {"on", "off", "power", "power_value"});
  if (!r.ok()) return;
  if (auto f = r.find("on")) set(code_line(f->value), codes.on);
  if (auto f = r.find("off")) set(code_line(f->value), codes.off);
  const auto* power = r.find("power");
  const auto* power_value = r.find("power_value");
  if (power) {
    if (auto text = code_line(power->value)) {
      if (text->find("{power}") == std::string::npos)
        sink_.error(power->value.mark, power->value.path +
                                           ": expected a template containing {power}, such as 'M68 E0 Q{power}', "
                                           "got '" + printable(*text) + "'");
      else
        codes.power_template = *text;
    }
    if (!power_value) r.require("power_value", "the value substituted for {power}");
  }
  if (power_value) {
    set(read_number(sink_, power_value->value, kPower, Bound::NonNegative), codes.power);
    if (!power)
      sink_.error(power_value->value.mark,
                  power_value->value.path + ": has no effect without a 'power' template such as 'M68 E0 Q{power}'");
  }
}

void MachineReader::check_head_tool_numbers() {
  std::map<int, std::size_t> first_head;
  for (std::size_t i = 0; i < machine_.heads.size() && i < head_tool_numbers_.size(); ++i) {
    const int number = machine_.heads[i].tool_number;
    const HeadToolNumber& at = head_tool_numbers_[i];
    const std::string what = at.given ? at.path + ": tool number " + std::to_string(number)
                                      : at.path + ": the default tool number " + std::to_string(number) +
                                            " (100 + the head's index)";
    const std::string fix = at.given ? "expected a T number no cutting tool or other head uses"
                                     : "set heads[" + std::to_string(i) +
                                           "].tool_number to a T number no cutting tool or other head uses";
    const auto tool = tool_numbers_.find(number);
    if (tool != tool_numbers_.end()) {
      sink_.error(at.mark, what + " is already the number of the cutting tool at line " + line_of(tool->second) +
                               "; " + fix);
      continue;
    }
    const auto [it, inserted] = first_head.emplace(number, i);
    if (!inserted)
      sink_.error(at.mark, what + " is already the tool number of head '" +
                               printable(machine_.heads[it->second].name) + "'; " + fix);
  }
}

// ------------------------------------------------------------ cutting tools

std::optional<std::size_t> MachineReader::read_tools(const Value& v) {
  const auto items = read_list(sink_, v, "cutting tools");
  if (!items) return std::nullopt;
  for (const auto& item : *items) read_tool(item);
  return items->size();
}

void MachineReader::read_tool(const Value& v) {
  MapReader r(sink_, v,
              {"number", "name", "type", "diameter", "corner_radius", "flute_length", "shank", "holder",
               "spindle_speed", "finish_spindle_speed", "feed", "plunge_feed", "finish_feed", "step_down", "step_over", "cost_per_mm3", "removal_rate", "wear", "primitives"});
  if (!r.ok()) return;
  const std::size_t before = sink_.count();
  CuttingTool t;
  read_tool_number_and_name(r, t);
  std::optional<ToolType> type;
  if (auto f = r.require("type")) type = read_enum(sink_, f->value, kToolTypes);
  set(type, t.type);
  const auto diameter = required_length(r, "diameter", t.diameter);
  read_corner_radius(r, type, diameter, t);

  const double d = t.diameter;
  t.flute_length = 3.0 * d;
  const auto flute_length = number(r, "flute_length", kLength, Bound::Positive, t.flute_length);
  t.shank = {d, 2.0 * d};
  if (auto f = r.find("shank")) read_tool_body(f->value, t.shank);
  if (auto f = r.find("holder")) read_tool_body(f->value, t.holder);
  number(r, "spindle_speed", kSpindleSpeed, Bound::Positive, t.spindle_speed);
  number(r, "finish_spindle_speed", kSpindleSpeed, Bound::Positive, t.finish_spindle_speed);
  number(r, "feed", kFeed, Bound::Positive, t.feed);
  number(r, "plunge_feed", kFeed, Bound::Positive, t.plunge_feed);
  number(r, "finish_feed", kFeed, Bound::Positive, t.finish_feed);
  read_steps(r, flute_length.has_value(), diameter, t);
  number(r, "cost_per_mm3", kCostFactor, Bound::NonNegative, t.cost_per_mm3);
  number(r, "removal_rate", kVolumeRate, Bound::Positive, t.removal_rate);
  if (auto f = r.find("wear")) {
    MapReader w(sink_, f->value, {"price", "life"});
    if (w.ok()) {
      number(w, "price", kMoney, Bound::NonNegative, t.tool_price);
      number(w, "life", kMinutes, Bound::Positive, t.tool_life);
    }
  }
  if (auto f = r.find("primitives")) t.primitives = primitives(f->value, kSubtractivePrimitives, t.primitives);

  // The assembly must fit under the spindle with the Z axis fully retracted.
  if (sink_.count() == before && z_travel_known_) {
    const double z_travel = machine_.envelope.z.travel.span();
    if (t.stick_out() > z_travel)
      sink_.error(v.mark, v.path + " (" + t.name + "): tool stick-out " + fmt(t.stick_out()) + " mm (flute " +
                              fmt(t.flute_length) + " + shank " + fmt(t.shank.length) + " + holder " +
                              fmt(t.holder.length) + ") exceeds the Z travel of " + fmt(z_travel) +
                              " mm; expected at most " + fmt(z_travel) + " mm");
  }
  machine_.tools.push_back(std::move(t));
}

void MachineReader::read_tool_number_and_name(MapReader& r, CuttingTool& t) {
  const Value* number_at = nullptr;
  bool number_unique = false;
  if (auto f = r.require("number")) {
    number_at = &f->value;
    if (auto n = read_integer(sink_, f->value, 1, kMaxToolNumber,
                              "a positive integer tool number (1.." + std::to_string(kMaxToolNumber) + ")")) {
      t.number = *n;
      const auto [it, inserted] = tool_numbers_.emplace(*n, f->value.mark);
      number_unique = inserted;
      if (!inserted)
        sink_.error(f->value.mark, f->value.path + ": duplicate tool number " + std::to_string(*n) +
                                       ", first used at line " + line_of(it->second));
    }
  }
  if (auto f = r.find("name")) {
    set(read_string(sink_, f->value, "a tool name"), t.name);
    if (!t.name.empty()) unique(tool_names_, t.name, f->value, "tool name");
  } else if (t.number > 0) {
    t.name = "T" + std::to_string(t.number);
    // A repeated number has been reported already; its default name would only repeat that.
    if (number_unique) unique(tool_names_, t.name, *number_at, "tool name");
  }
}

// Corner radius: flat 0, ball d/2, bull strictly between.
void MachineReader::read_corner_radius(MapReader& r, std::optional<ToolType> type,
                                       std::optional<double> diameter, CuttingTool& t) {
  const auto* radius_field = r.find("corner_radius");
  std::optional<double> radius;
  if (radius_field) radius = read_number(sink_, radius_field->value, kLength, Bound::NonNegative);
  if (!type || !diameter) return;
  const double half = *diameter / 2.0;
  const auto bad_radius = [&](const std::string& expected) {
    sink_.error(radius_field->value.mark, radius_field->value.path + ": expected " + expected + ", got " +
                                              describe(radius_field->value.node));
  };
  switch (*type) {
    case ToolType::Flat:
      if (radius && *radius != 0.0) bad_radius("0 for a flat end mill (use type: bull for a corner radius)");
      t.corner_radius = 0.0;
      break;
    case ToolType::Ball:
      if (radius && std::abs(*radius - half) > 1e-9 * std::max(1.0, half))
        bad_radius("diameter/2 = " + fmt(half) + " mm for a ball end mill");
      t.corner_radius = half;
      break;
    case ToolType::Bull:
      if (!radius_field)
        r.require("corner_radius", "a bull-nose end mill needs 0 < corner_radius < diameter/2");
      else if (radius && !(*radius > 0.0 && *radius < half))
        bad_radius("a corner radius between 0 and diameter/2 = " + fmt(half) + " mm (exclusive) for a bull-nose "
                   "end mill");
      else if (radius)
        t.corner_radius = *radius;
      break;
  }
}

// Step-down at most the flute length, step-over at most the diameter (when those are known).
void MachineReader::read_steps(const MapReader& r, bool flute_length_read, std::optional<double> diameter,
                               CuttingTool& t) {
  const double d = t.diameter;
  t.step_down = 0.5 * d;
  if (auto f = r.find("step_down")) {
    if (auto sd = read_number(sink_, f->value, kLength, Bound::Positive)) {
      const bool flute_known = flute_length_read || (!r.find("flute_length") && diameter);
      if (flute_known && *sd > t.flute_length)
        sink_.error(f->value.mark, f->value.path + ": expected at most the flute length " + fmt(t.flute_length) +
                                       " mm, got " + describe(f->value.node));
      t.step_down = *sd;
    }
  }
  t.step_over = 0.4 * d;
  if (auto f = r.find("step_over")) {
    if (auto so = read_number(sink_, f->value, kLength, Bound::Positive)) {
      if (diameter && *so > *diameter)
        sink_.error(f->value.mark, f->value.path + ": expected at most the tool diameter " + fmt(*diameter) +
                                       " mm, got " + describe(f->value.node));
      t.step_over = *so;
    }
  }
}

void MachineReader::read_tool_body(const Value& v, ToolBody& body) {
  MapReader r(sink_, v, {"diameter", "length"});
  if (!r.ok()) return;
  number(r, "diameter", kLength, Bound::Positive, body.diameter);
  number(r, "length", kLength, Bound::Positive, body.length);
}

}  // namespace hybridctl::config::detail
