// The machine-file schema's top level: which sections a machine file has and in what
// order they are read (tools before the heads' T numbers are checked, the envelope
// before setups), the readers the sections share, and the small sections (planning,
// transports, gcode).

#include <algorithm>

#include "config/machine_reader.hpp"
#include "config/transport_uri.hpp"

namespace hybridctl::config::detail {

namespace {

constexpr long kMaxProgramNumber = 9999;
constexpr long kMaxTopK = 1000;

const std::vector<std::pair<std::string_view, Dialect>> kDialects = {{"rs274ngc", Dialect::Rs274ngc},
                                                                    {"fanuc", Dialect::Fanuc}};
const std::vector<std::string_view> kTopLevelKeys = {"name",  "description", "envelope", "heads", "tools",
                                                     "setups", "raw_stocks", "planning", "costs", "transports",
                                                     "gcode"};
const std::vector<std::pair<std::string_view, Objective>> kObjectives = {
    {"money", Objective::Money}, {"time", Objective::Time}, {"cost-factor", Objective::CostFactor}};

}  // namespace

Machine MachineReader::load(const YAML::Node& root) {
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
  // A machine file that prices its time plans by money unless it says otherwise.
  if (auto f = r.find("costs")) {
    read_costs(f->value);
    machine_.planning.objective = Objective::Money;
  }
  if (auto f = r.find("planning")) read_planning(f->value);
  if (auto f = r.find("transports")) read_transports(f->value);
  if (auto f = r.find("gcode")) read_gcode(f->value);
  return machine_;
}

std::optional<double> MachineReader::number(const MapReader& r, std::string_view key, Quantity q, Bound bound, double& target) {
  const auto* f = r.find(key);
  if (!f) return std::nullopt;
  auto value = read_number(sink_, f->value, q, bound);
  set(value, target);
  return value;
}

std::optional<double> MachineReader::required_length(MapReader& r, std::string_view key, double& target) {
  const auto* f = r.require(key);
  if (!f) return std::nullopt;
  auto value = read_number(sink_, f->value, kLength, Bound::Positive);
  set(value, target);
  return value;
}

std::optional<std::string> MachineReader::code_line(const Value& v) {
  auto text = read_string(sink_, v, "a line of G-code words such as 'M64 P0'");
  if (text && text->find_first_of("\r\n") != std::string::npos) {
    sink_.error(v.mark, v.path + ": expected a single line of G-code words, got several lines");
    return std::nullopt;
  }
  return text;
}

void MachineReader::unique(std::map<std::string, YAML::Mark>& seen, const std::string& name, const Value& at,
    std::string_view what) {
  const auto [it, inserted] = seen.emplace(name, at.mark);
  if (!inserted)
    sink_.error(at.mark, at.path + ": duplicate " + std::string(what) + " '" + printable(name) +
                             "', first used at line " + line_of(it->second));
}

std::vector<PrimitiveKind> MachineReader::primitives(const Value& v,
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

// ------------------------------------------------------------ planning

void MachineReader::read_planning(const Value& v) {
  MapReader r(sink_, v, {"voxel_size", "tolerance", "sliver_threshold", "top_k", "objective", "fixed_costs"});
  if (!r.ok()) return;
  Planning& p = machine_.planning;
  number(r, "voxel_size", kLength, Bound::Positive, p.voxel_size);
  number(r, "tolerance", kLength, Bound::NonNegative, p.tolerance);
  number(r, "sliver_threshold", kVolume, Bound::NonNegative, p.sliver_threshold);
  if (auto f = r.find("top_k"))
    set(read_integer(sink_, f->value, 1, kMaxTopK, "an integer number of plans from 1 to " + std::to_string(kMaxTopK)),
        p.top_k);
  if (auto f = r.find("objective")) set(read_enum(sink_, f->value, kObjectives), p.objective);
  if (auto f = r.find("fixed_costs")) {
    MapReader c(sink_, f->value, {"tool_change", "setup_change", "mode_switch"});
    if (c.ok()) {
      number(c, "tool_change", kCost, Bound::NonNegative, p.tool_change_cost);
      number(c, "setup_change", kCost, Bound::NonNegative, p.setup_change_cost);
      number(c, "mode_switch", kCost, Bound::NonNegative, p.mode_switch_cost);
    }
  }
}

// ------------------------------------------------------------ costs

void MachineReader::read_costs(const Value& v) {
  MapReader r(sink_, v, {"currency", "machine_rate", "tool_change", "head_switch", "setup_change", "refixture"});
  if (!r.ok()) return;
  Costs& c = machine_.costs;
  if (auto f = r.find("currency")) {
    const auto text = read_string(sink_, f->value, "a currency label such as EUR or USD");
    if (text && (text->empty() || text->size() > 8 || text->find_first_of(" \t\r\n") != std::string::npos))
      sink_.error(f->value.mark, f->value.path + ": expected a short currency label such as EUR or USD, got " +
                                     describe(f->value.node));
    else
      set(text, c.currency);
  }
  number(r, "machine_rate", kHourlyRate, Bound::NonNegative, c.machine_rate);
  number(r, "tool_change", kSeconds, Bound::NonNegative, c.tool_change);
  number(r, "head_switch", kSeconds, Bound::NonNegative, c.head_switch);
  number(r, "setup_change", kSeconds, Bound::NonNegative, c.setup_change);
  number(r, "refixture", kMinutes, Bound::NonNegative, c.refixture);
}

// ------------------------------------------------------------ transports

void MachineReader::read_transports(const Value& v) {
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

void MachineReader::read_gcode(const Value& v) {
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

void MachineReader::read_m_codes(const Value& v, MCodes& codes) {
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

}  // namespace hybridctl::config::detail
