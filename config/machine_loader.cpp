// The machine-file schema: which keys each mapping has, what each value must be, and the
// checks that relate values to each other (layer height vs bead, tool length vs Z travel,
// setup rotary positions vs axis ranges, unique names and tool numbers).

#include "config/machine_loader.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>
#include <system_error>

#include <yaml-cpp/eventhandler.h>

#include "config/transport_uri.hpp"
#include "config/yaml_reader.hpp"

namespace hybridctl::config {

namespace {

using namespace detail;

/// Larger files are rejected before parsing; a real machine file is a few kB.
constexpr std::size_t kMaxMachineFileBytes = 16u << 20;
constexpr long kMaxToolNumber = 99999;
constexpr long kMaxProgramNumber = 9999;
constexpr long kMaxTopK = 1000;

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
const std::vector<std::pair<std::string_view, Approach>> kApproaches = {
    {"+X", Approach::PlusX}, {"-X", Approach::MinusX}, {"+Y", Approach::PlusY},
    {"-Y", Approach::MinusY}, {"+Z", Approach::PlusZ}, {"-Z", Approach::MinusZ}};
const std::vector<std::pair<std::string_view, int>> kWorkOffsets = {{"G54", 54}, {"G55", 55}, {"G56", 56},
                                                                   {"G57", 57}, {"G58", 58}, {"G59", 59}};
const std::vector<std::pair<std::string_view, Axis>> kAxes = {{"X", Axis::X}, {"Y", Axis::Y}, {"Z", Axis::Z}};
const std::vector<std::pair<std::string_view, Dialect>> kDialects = {{"rs274ngc", Dialect::Rs274ngc},
                                                                    {"fanuc", Dialect::Fanuc}};

const std::vector<std::string_view> kTopLevelKeys = {"name",  "description", "envelope", "heads", "tools",
                                                     "setups", "raw_stocks", "planning", "transports", "gcode"};

std::string fmt(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

std::string line_of(const YAML::Mark& m) { return std::to_string(m.is_null() ? 1 : m.line + 1); }

/// Reads a whole machine document into a Machine, reporting through the sink.
class Loader {
 public:
  explicit Loader(DiagnosticSink& sink) : sink_(sink) {}

  Machine load(const YAML::Node& root) {
    const Value v{root, "", root.Mark()};
    MapReader r(sink_, v, kTopLevelKeys);
    if (!r.ok()) return machine_;
    if (auto f = r.require("name")) set(read_string(sink_, f->value, "the machine's name"), machine_.name);
    if (auto f = r.find("description")) set(read_string(sink_, f->value, "a description"), machine_.description);
    if (auto f = r.require("envelope")) read_envelope(f->value);
    // At least one head or tool in all; lists that are not lists have been reported already.
    const auto* heads_field = r.find("heads");
    const auto* tools_field = r.find("tools");
    const auto heads = heads_field ? read_heads(heads_field->value) : std::optional<std::size_t>(0);
    const auto tools = tools_field ? read_tools(tools_field->value) : std::optional<std::size_t>(0);
    if (!heads_field && !tools_field)
      sink_.error(v.mark, "missing required field 'heads' or 'tools' (at least one additive head or cutting tool)");
    else if (heads && tools && *heads + *tools == 0)
      sink_.error((heads_field ? heads_field : tools_field)->value.mark,
                  "expected at least one additive head under 'heads' or cutting tool under 'tools', got none");
    check_head_tool_numbers();
    if (auto f = r.require("setups")) read_setups(f->value);
    if (auto f = r.find("raw_stocks")) read_raw_stocks(f->value);
    if (auto f = r.find("planning")) read_planning(f->value);
    if (auto f = r.find("transports")) read_transports(f->value);
    if (auto f = r.find("gcode")) read_gcode(f->value);
    return machine_;
  }

 private:
  template <class T>
  static void set(const std::optional<T>& value, T& target) {
    if (value) target = *value;
  }

  /// Sets `target` when `key` is present and valid; returns the value read, if any.
  std::optional<double> number(const MapReader& r, std::string_view key, Quantity q, Bound bound, double& target) {
    const auto* f = r.find(key);
    if (!f) return std::nullopt;
    auto value = read_number(sink_, f->value, q, bound);
    set(value, target);
    return value;
  }

  /// A required positive length.
  std::optional<double> required_length(MapReader& r, std::string_view key, double& target) {
    const auto* f = r.require(key);
    if (!f) return std::nullopt;
    auto value = read_number(sink_, f->value, kLength, Bound::Positive);
    set(value, target);
    return value;
  }

  /// One line of G-code or M-code words, e.g. "M64 P0".
  std::optional<std::string> code_line(const Value& v) {
    auto text = read_string(sink_, v, "a line of G-code words such as 'M64 P0'");
    if (text && text->find_first_of("\r\n") != std::string::npos) {
      sink_.error(v.mark, v.path + ": expected a single line of G-code words, got several lines");
      return std::nullopt;
    }
    return text;
  }

  /// Reports a duplicate name; `seen` maps names to the line of their first use.
  void unique(std::map<std::string, YAML::Mark>& seen, const std::string& name, const Value& at,
              std::string_view what) {
    const auto [it, inserted] = seen.emplace(name, at.mark);
    if (!inserted)
      sink_.error(at.mark, at.path + ": duplicate " + std::string(what) + " '" + printable(name) +
                               "', first used at line " + line_of(it->second));
  }

  std::vector<PrimitiveKind> primitives(const Value& v,
                                        const std::vector<std::pair<std::string_view, PrimitiveKind>>& choices,
                                        std::vector<PrimitiveKind> fallback) {
    const auto items = read_list(sink_, v, "primitive kinds");
    if (!items) return fallback;
    std::vector<std::string_view> names;
    for (const auto& c : choices) names.push_back(c.first);
    if (items->empty()) {
      sink_.error(v.mark, v.path + ": expected at least one of " + join(names) + ", got an empty list");
      return fallback;
    }
    std::vector<PrimitiveKind> kinds;
    for (const auto& item : *items) {
      const auto kind = read_enum(sink_, item, choices);
      if (!kind) continue;
      if (std::find(kinds.begin(), kinds.end(), *kind) != kinds.end()) {
        sink_.error(item.mark, item.path + ": '" + std::string(to_string(*kind)) + "' is listed twice");
        continue;
      }
      kinds.push_back(*kind);
    }
    return kinds.empty() ? fallback : kinds;
  }

  // ------------------------------------------------------------ envelope

  void read_envelope(const Value& v) {
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

  /// Returns whether the travel was read.
  bool read_linear_axis(const Value& v, LinearAxis& axis) {
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

  void read_rotary_axis(const Value& v, char name) {
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

  std::optional<std::size_t> read_heads(const Value& v) {
    const auto items = read_list(sink_, v, "additive heads");
    if (!items) return std::nullopt;
    for (const auto& item : *items) read_head(item);
    return items->size();
  }

  void read_head(const Value& v) {
    MapReader r(sink_, v,
                {"name", "process", "bead", "nozzle", "layer_height", "hatch_spacing", "travel_clearance", "feed",
                 "tool_number", "codes", "cost_per_mm3", "primitives"});
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
    if (auto f = r.find("nozzle")) {
      MapReader n(sink_, f->value, {"diameter", "length"});
      if (n.ok()) {
        Nozzle nozzle;
        const auto d = required_length(n, "diameter", nozzle.diameter);
        const auto l = required_length(n, "length", nozzle.length);
        if (d && l) h.nozzle = nozzle;
      }
    }

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
    if (auto f = r.find("codes")) read_deposition_codes(f->value, h.codes);
    if (auto f = r.find("primitives")) h.primitives = primitives(f->value, kAdditivePrimitives, h.primitives);
    machine_.heads.push_back(std::move(h));
  }

  void read_deposition_codes(const Value& v, DepositionCodes& codes) {
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

  /// Head tool numbers are unique among heads and never a cutting tool's number.
  void check_head_tool_numbers() {
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

  std::optional<std::size_t> read_tools(const Value& v) {
    const auto items = read_list(sink_, v, "cutting tools");
    if (!items) return std::nullopt;
    for (const auto& item : *items) read_tool(item);
    return items->size();
  }

  void read_tool(const Value& v) {
    MapReader r(sink_, v,
                {"number", "name", "type", "diameter", "corner_radius", "flute_length", "shank", "holder",
                 "spindle_speed", "feed", "plunge_feed", "step_down", "step_over", "cost_per_mm3", "primitives"});
    if (!r.ok()) return;
    const std::size_t before = sink_.count();
    CuttingTool t;

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

    std::optional<ToolType> type;
    if (auto f = r.require("type")) type = read_enum(sink_, f->value, kToolTypes);
    set(type, t.type);
    const auto diameter = required_length(r, "diameter", t.diameter);

    // Corner radius: flat 0, ball d/2, bull strictly between.
    const auto* radius_field = r.find("corner_radius");
    std::optional<double> radius;
    if (radius_field) radius = read_number(sink_, radius_field->value, kLength, Bound::NonNegative);
    if (type && diameter) {
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

    const double d = t.diameter;
    t.flute_length = 3.0 * d;
    const auto flute_length = number(r, "flute_length", kLength, Bound::Positive, t.flute_length);
    t.shank = {d, 2.0 * d};
    if (auto f = r.find("shank")) read_tool_body(f->value, t.shank);
    if (auto f = r.find("holder")) read_tool_body(f->value, t.holder);
    number(r, "spindle_speed", kSpindleSpeed, Bound::Positive, t.spindle_speed);
    number(r, "feed", kFeed, Bound::Positive, t.feed);
    number(r, "plunge_feed", kFeed, Bound::Positive, t.plunge_feed);

    t.step_down = 0.5 * d;
    if (auto f = r.find("step_down")) {
      if (auto sd = read_number(sink_, f->value, kLength, Bound::Positive)) {
        const bool flute_known = flute_length || (!r.find("flute_length") && diameter);
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
    number(r, "cost_per_mm3", kCostFactor, Bound::NonNegative, t.cost_per_mm3);
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

  void read_tool_body(const Value& v, ToolBody& body) {
    MapReader r(sink_, v, {"diameter", "length"});
    if (!r.ok()) return;
    number(r, "diameter", kLength, Bound::Positive, body.diameter);
    number(r, "length", kLength, Bound::Positive, body.length);
  }

  // ------------------------------------------------------------ setups

  void read_setups(const Value& v) {
    const auto items = read_list(sink_, v, "setups");
    if (!items) return;
    if (items->empty()) sink_.error(v.mark, v.path + ": expected at least one setup, got an empty list");
    for (const auto& item : *items) read_setup(item);
  }

  void read_setup(const Value& v) {
    MapReader r(sink_, v,
                {"name", "description", "approach", "work_offset", "work_origin", "manual_refixture", "rotary"});
    if (!r.ok()) return;
    Setup s;
    const Envelope& e = machine_.envelope;
    s.work_origin = {0.5 * (e.x.travel.min + e.x.travel.max), 0.5 * (e.y.travel.min + e.y.travel.max),
                     e.z.travel.min};
    if (auto f = r.require("name")) {
      set(read_string(sink_, f->value, "a setup name"), s.name);
      if (!s.name.empty()) unique(setup_names_, s.name, f->value, "setup name");
    }
    if (auto f = r.find("description")) set(read_string(sink_, f->value, "a description"), s.description);
    if (auto f = r.find("approach")) set(read_enum(sink_, f->value, kApproaches), s.approach);
    const auto* offset_field = r.find("work_offset");
    if (offset_field) set(read_enum(sink_, offset_field->value, kWorkOffsets), s.work_offset);
    if (auto f = r.find("work_origin")) read_work_origin(f->value, s);
    // Setups that share a work offset share its origin: G54 can only mean one place.
    for (const auto& other : machine_.setups) {
      if (other.work_offset != s.work_offset || other.work_origin == s.work_origin) continue;
      const Value& at = offset_field ? offset_field->value : v;
      sink_.error(at.mark, at.path + ": G" + std::to_string(s.work_offset) + " is already the work offset of setup '" +
                               printable(other.name) + "' with another work_origin; expected a work offset of its "
                               "own or the same work_origin");
      break;
    }
    if (auto f = r.find("manual_refixture")) set(read_bool(sink_, f->value), s.manual_refixture);
    if (auto f = r.find("rotary")) read_rotary_positions(f->value, s);
    machine_.setups.push_back(std::move(s));
  }

  void read_work_origin(const Value& v, Setup& s) {
    constexpr std::string_view kExpected = "expected the machine coordinates of the work zero as [x, y, z] in mm";
    if (!v.node.IsSequence() || v.node.size() != 3) {
      const std::string got = v.node.IsSequence() ? "a list of " + std::to_string(v.node.size()) : describe(v.node);
      sink_.error(v.mark, v.path + ": " + std::string(kExpected) + ", got " + got);
      return;
    }
    const auto items = read_list(sink_, v, "coordinates");
    for (std::size_t i = 0; i < 3; ++i) set(read_number(sink_, (*items)[i], kLength, Bound::Any), s.work_origin[i]);
  }

  void read_rotary_positions(const Value& v, Setup& s) {
    MapReader r(sink_, v, {});
    if (!r.ok()) return;
    std::string machine_axes;
    for (const auto& a : machine_.envelope.rotary) machine_axes += (machine_axes.empty() ? "" : ", ") + std::string(1, a.name);
    for (const auto& f : r.fields()) {
      if (f.key != "A" && f.key != "B" && f.key != "C") {
        sink_.error(f.key_mark, f.value.path + ": expected a rotary axis name A, B or C" +
                                    (machine_axes.empty() ? std::string() : " (this machine has " + machine_axes + ")"));
        continue;
      }
      const auto degrees = read_number(sink_, f.value, kAngle, Bound::Any);
      if (!rotary_axes_known_) continue;  // the envelope has problems of its own
      const RotaryAxis* axis = machine_.envelope.find_rotary(f.key[0]);
      if (!axis) {
        sink_.error(f.key_mark, f.value.path + ": the machine has no " + f.key + " axis; " +
                                    (machine_axes.empty() ? std::string("it has no rotary axes")
                                                          : "its rotary axes are " + machine_axes));
        continue;
      }
      if (!degrees) continue;
      if (!axis->range.contains(*degrees)) {
        sink_.error(f.value.mark, f.value.path + ": expected an angle within the " + f.key + " axis range [" +
                                      fmt(axis->range.min) + ", " + fmt(axis->range.max) + "] degrees, got " +
                                      describe(f.value.node));
        continue;
      }
      s.rotary.push_back(RotaryPosition{f.key[0], *degrees});
    }
  }

  // ------------------------------------------------------------ raw stocks

  void read_raw_stocks(const Value& v) {
    machine_.raw_stocks.clear();
    const auto items = read_list(sink_, v, "raw stocks");
    if (!items) return;
    for (const auto& item : *items) read_raw_stock(item);
  }

  void read_raw_stock(const Value& v) {
    MapReader r(sink_, v, {"name", "box", "round_bar"});
    if (!r.ok()) return;
    RawStock stock;
    if (auto f = r.require("name")) {
      set(read_string(sink_, f->value, "a raw stock name"), stock.name);
      if (!stock.name.empty()) unique(stock_names_, stock.name, f->value, "raw stock name");
    }
    const auto* box = r.find("box");
    const auto* bar = r.find("round_bar");
    if (!box && !bar) {
      sink_.error(v.mark, v.path + ": missing the stock's shape; expected exactly one of 'box' or 'round_bar'");
    } else if (box && bar) {
      const auto& second = box->key_mark.line > bar->key_mark.line ? *box : *bar;
      sink_.error(second.key_mark, v.path + ": expected exactly one of 'box' or 'round_bar', got both");
    } else if (box) {
      stock.kind = RawStock::Kind::Box;
      MapReader b(sink_, box->value, {"margin"});
      if (b.ok())
        if (auto m = b.find("margin")) read_margin(m->value, stock);
    } else {
      stock.kind = RawStock::Kind::RoundBar;
      MapReader b(sink_, bar->value, {"diameter", "length", "axis"});
      if (b.ok()) {
        required_length(b, "diameter", stock.bar_diameter);
        required_length(b, "length", stock.bar_length);
        if (auto a = b.find("axis")) set(read_enum(sink_, a->value, kAxes), stock.bar_axis);
      }
    }
    machine_.raw_stocks.push_back(std::move(stock));
  }

  void read_margin(const Value& v, RawStock& stock) {
    if (v.node.IsSequence()) {
      if (v.node.size() != 3) {
        sink_.error(v.mark, v.path + ": expected a margin in mm as a number or [x, y, z], got a list of " +
                                std::to_string(v.node.size()));
        return;
      }
      const auto items = read_list(sink_, v, "margins");
      for (std::size_t i = 0; i < 3; ++i)
        set(read_number(sink_, (*items)[i], kLength, Bound::NonNegative), stock.margin[i]);
      return;
    }
    if (!v.node.IsScalar()) {
      sink_.error(v.mark, v.path + ": expected a margin in mm as a number or [x, y, z], got " + describe(v.node));
      return;
    }
    if (auto m = read_number(sink_, v, kLength, Bound::NonNegative)) stock.margin = {*m, *m, *m};
  }

  // ------------------------------------------------------------ planning

  void read_planning(const Value& v) {
    MapReader r(sink_, v, {"voxel_size", "tolerance", "sliver_threshold", "top_k", "fixed_costs"});
    if (!r.ok()) return;
    Planning& p = machine_.planning;
    number(r, "voxel_size", kLength, Bound::Positive, p.voxel_size);
    number(r, "tolerance", kLength, Bound::NonNegative, p.tolerance);
    number(r, "sliver_threshold", kVolume, Bound::NonNegative, p.sliver_threshold);
    if (auto f = r.find("top_k"))
      set(read_integer(sink_, f->value, 1, kMaxTopK, "an integer number of plans from 1 to " + std::to_string(kMaxTopK)),
          p.top_k);
    if (auto f = r.find("fixed_costs")) {
      MapReader c(sink_, f->value, {"tool_change", "setup_change", "mode_switch"});
      if (c.ok()) {
        number(c, "tool_change", kCost, Bound::NonNegative, p.tool_change_cost);
        number(c, "setup_change", kCost, Bound::NonNegative, p.setup_change_cost);
        number(c, "mode_switch", kCost, Bound::NonNegative, p.mode_switch_cost);
      }
    }
  }

  // ------------------------------------------------------------ transports

  void read_transports(const Value& v) {
    MapReader r(sink_, v, {});
    if (!r.ok()) return;
    for (const auto& f : r.fields()) {
      const auto uri = read_string(sink_, f.value, std::string("a transport URI, one of ") + std::string(kTransportUriForms));
      if (!uri) continue;
      if (uri->find_first_of(" \t\r\n") != std::string::npos ||
          std::any_of(uri->begin(), uri->end(), [](char c) { return static_cast<unsigned char>(c) < 0x20; })) {
        sink_.error(f.value.mark, f.value.path + ": bad transport URI '" + printable(*uri) +
                                      "': contains spaces or control characters; expected one of " +
                                      std::string(kTransportUriForms));
        continue;
      }
      auto parsed = parse_transport_uri(*uri);
      if (!parsed.transport) {
        sink_.error(f.value.mark, f.value.path + ": bad transport URI '" + printable(*uri) + "': " + parsed.error);
        continue;
      }
      parsed.transport->name = f.key;
      machine_.transports.push_back(std::move(*parsed.transport));
    }
  }

  // ------------------------------------------------------------ G-code

  void read_gcode(const Value& v) {
    MapReader r(sink_, v, {"dialect", "program_number", "m_codes"});
    if (!r.ok()) return;
    GcodeSettings& g = machine_.gcode;
    if (auto f = r.find("dialect")) set(read_enum(sink_, f->value, kDialects), g.dialect);
    if (g.dialect == Dialect::Fanuc) g.m_codes.program_end = "M30";
    if (auto f = r.find("program_number"))
      set(read_integer(sink_, f->value, 1, kMaxProgramNumber,
                       "a program number from 1 to " + std::to_string(kMaxProgramNumber)),
          g.program_number);
    if (auto f = r.find("m_codes")) read_m_codes(f->value, g.m_codes);
  }

  void read_m_codes(const Value& v, MCodes& codes) {
    const std::vector<std::pair<std::string_view, std::string MCodes::*>> entries = {
        {"program_stop", &MCodes::program_stop}, {"optional_stop", &MCodes::optional_stop},
        {"program_end", &MCodes::program_end},   {"spindle_cw", &MCodes::spindle_cw},
        {"spindle_ccw", &MCodes::spindle_ccw},   {"spindle_stop", &MCodes::spindle_stop},
        {"tool_change", &MCodes::tool_change},   {"coolant_on", &MCodes::coolant_on},
        {"coolant_off", &MCodes::coolant_off}};
    std::vector<std::string_view> names;
    for (const auto& e : entries) names.push_back(e.first);
    MapReader r(sink_, v, names);
    if (!r.ok()) return;
    for (const auto& [name, member] : entries) {
      const auto* f = r.find(name);
      if (!f) continue;
      const auto& node = f->value.node;
      const bool well_formed = node.IsScalar() && node.Scalar().size() >= 2 && node.Scalar().size() <= 5 &&
                               node.Scalar()[0] == 'M' &&
                               std::all_of(node.Scalar().begin() + 1, node.Scalar().end(),
                                           [](char c) { return c >= '0' && c <= '9'; });
      if (!well_formed) {
        sink_.error(f->value.mark, f->value.path + ": expected an M code such as M30, got " + describe(node));
        continue;
      }
      codes.*member = node.Scalar();
    }
  }

  DiagnosticSink& sink_;
  Machine machine_;
  bool z_travel_known_ = false;
  bool rotary_axes_known_ = false;
  std::map<std::string, YAML::Mark> head_names_, tool_names_, setup_names_, stock_names_;
  std::map<int, YAML::Mark> tool_numbers_;
  /// Where each head's tool number was given (or the head, for the default), by head index.
  struct HeadToolNumber {
    YAML::Mark mark;
    std::string path;
    bool given = false;
  };
  std::vector<HeadToolNumber> head_tool_numbers_;
};

/// Where each document of a stream starts; the parser's events are otherwise ignored.
///
/// yaml-cpp 0.7 reads a document that starts with a token no value can start with (a stray
/// ',', say) as null without consuming that token, so YAML::LoadAll calls the parser again
/// and again on it, allocating without end (jbeder/yaml-cpp#1040, fixed in 0.8). The loader
/// takes at most two parser steps instead: the first document, and whether another follows
/// (one that starts where the first did is that stuck token).
class DocumentStarts final : public YAML::EventHandler {
 public:
  std::vector<YAML::Mark> marks;

  void OnDocumentStart(const YAML::Mark& mark) override { marks.push_back(mark); }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark&, YAML::anchor_t) override {}
  void OnAlias(const YAML::Mark&, YAML::anchor_t) override {}
  void OnScalar(const YAML::Mark&, const std::string&, YAML::anchor_t, const std::string&) override {}
  void OnSequenceStart(const YAML::Mark&, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {}
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark&, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {}
  void OnMapEnd() override {}
};

}  // namespace

Machine parse_machine(std::string_view yaml_text, std::string file_name) {
  DiagnosticSink sink(std::move(file_name));
  Machine machine;
  constexpr std::string_view kExpectedDocument =
      "expected a mapping with at least name, envelope, setups and heads or tools (see docs/machine-file.md)";
  try {
    const std::string text(yaml_text);
    std::istringstream stream(text);
    YAML::Parser parser(stream);
    DocumentStarts starts;
    const bool second = parser.HandleNextDocument(starts) && parser.HandleNextDocument(starts);
    const YAML::Node document = YAML::Load(text);  // the first document
    if (second && starts.marks[1].pos == starts.marks[0].pos) {
      const auto at = static_cast<std::size_t>(std::max(starts.marks[0].pos, 0));
      sink.error(starts.marks[0], "YAML syntax error: found '" + printable(yaml_text.substr(at, 1)) +
                                      "', which starts no value; " + std::string(kExpectedDocument));
    } else if (!document || document.IsNull()) {
      sink.error(YAML::Mark::null_mark(), "empty machine file; " + std::string(kExpectedDocument));
    } else {
      if (second)
        sink.error(starts.marks[1], "a machine file holds one YAML document; expected no second document here");
      if (!document.IsMap())
        sink.error(document.Mark(), std::string(kExpectedDocument) + ", got " + describe(document));
      else
        machine = Loader(sink).load(document);
    }
  } catch (const YAML::Exception& e) {
    sink.error(e.mark, "YAML syntax error: " + e.msg);
  } catch (const std::exception& e) {
    sink.error(YAML::Mark::null_mark(), std::string("cannot parse: ") + e.what());
  }
  if (!sink.empty()) throw MachineFileError(sink.take_sorted());
  return machine;
}

Machine load_machine(const std::filesystem::path& path) {
  const std::string name = path.string();
  const auto fail = [&name](const std::string& why) {
    return MachineFileError({Diagnostic{name, 0, 0, why}});
  };
  const auto system_error = [](int code) { return std::generic_category().message(code); };

  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw fail("cannot read: " + system_error(errno));
  std::string text;
  int read_error = 0;
  struct stat info {};
  if (::fstat(fd, &info) != 0) {
    read_error = errno;
  } else if (S_ISDIR(info.st_mode)) {
    read_error = EISDIR;
  } else {
    char buffer[1 << 16];
    while (true) {
      const ssize_t n = ::read(fd, buffer, sizeof buffer);
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) {
        read_error = errno;
        break;
      }
      if (n == 0) break;
      text.append(buffer, static_cast<std::size_t>(n));
      if (text.size() > kMaxMachineFileBytes) {
        ::close(fd);
        throw fail("cannot read: file too large; a machine file is at most " +
                   std::to_string(kMaxMachineFileBytes >> 20) + " MiB");
      }
    }
  }
  ::close(fd);
  if (read_error != 0) throw fail("cannot read: " + system_error(read_error));
  return parse_machine(text, name);
}

}  // namespace hybridctl::config
