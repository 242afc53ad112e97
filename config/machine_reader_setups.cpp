// The work-holding sections: setups (approach, work offset and origin, rotary positions
// against the axes' ranges) and raw stocks (a box with margins, a round bar or a plate).

#include <algorithm>

#include "config/machine_reader.hpp"

namespace hybridctl::config::detail {

namespace {

const std::vector<std::pair<std::string_view, Approach>> kApproaches = {
    {"+X", Approach::PlusX}, {"-X", Approach::MinusX}, {"+Y", Approach::PlusY},
    {"-Y", Approach::MinusY}, {"+Z", Approach::PlusZ}, {"-Z", Approach::MinusZ}};
const std::vector<std::pair<std::string_view, int>> kWorkOffsets = {{"G54", 54}, {"G55", 55}, {"G56", 56},
                                                                   {"G57", 57}, {"G58", 58}, {"G59", 59}};
const std::vector<std::pair<std::string_view, Axis>> kAxes = {{"X", Axis::X}, {"Y", Axis::Y}, {"Z", Axis::Z}};

}  // namespace

// ------------------------------------------------------------ setups

void MachineReader::read_setups(const Value& v) {
  const auto items = read_list(sink_, v, "setups");
  if (!items) return;
  if (items->empty()) sink_.error(v.mark, v.path + ": expected at least one setup, got an empty list");
  for (const auto& item : *items) read_setup(item);
}

void MachineReader::read_setup(const Value& v) {
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

void MachineReader::read_work_origin(const Value& v, Setup& s) {
  constexpr std::string_view kExpected = "expected the machine coordinates of the work zero as [x, y, z] in mm";
  if (!v.node.IsSequence() || v.node.size() != 3) {
    const std::string got = v.node.IsSequence() ? "a list of " + std::to_string(v.node.size()) : describe(v.node);
    sink_.error(v.mark, v.path + ": " + std::string(kExpected) + ", got " + got);
    return;
  }
  const auto items = read_list(sink_, v, "coordinates");
  for (std::size_t i = 0; i < 3; ++i) set(read_number(sink_, (*items)[i], kLength, Bound::Any), s.work_origin[i]);
}

void MachineReader::read_rotary_positions(const Value& v, Setup& s) {
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

void MachineReader::read_raw_stocks(const Value& v) {
  machine_.raw_stocks.clear();
  const auto items = read_list(sink_, v, "raw stocks");
  if (!items) return;
  for (const auto& item : *items) read_raw_stock(item);
}

void MachineReader::read_raw_stock(const Value& v) {
  MapReader r(sink_, v, {"name", "box", "round_bar", "plate", "density", "price_per_kg"});
  if (!r.ok()) return;
  RawStock stock;
  if (auto f = r.require("name")) {
    set(read_string(sink_, f->value, "a raw stock name"), stock.name);
    if (!stock.name.empty()) unique(stock_names_, stock.name, f->value, "raw stock name");
  }
  const auto* box = r.find("box");
  const auto* bar = r.find("round_bar");
  const auto* plate = r.find("plate");
  std::vector<const MapReader::Field*> shapes;
  for (const auto* f : {box, bar, plate})
    if (f) shapes.push_back(f);
  std::sort(shapes.begin(), shapes.end(), [](const auto* a, const auto* b) { return a->key_mark.line < b->key_mark.line; });
  if (shapes.empty()) {
    sink_.error(v.mark, v.path + ": missing the stock's shape; expected exactly one of 'box', 'round_bar' or 'plate'");
  } else if (shapes.size() > 1) {
    sink_.error(shapes[1]->key_mark, v.path + ": expected exactly one of 'box', 'round_bar' or 'plate', got " +
                                         std::to_string(shapes.size()));
  } else if (plate) {
    stock.kind = RawStock::Kind::Plate;
    stock.margin = {0, 0, 0};
    MapReader b(sink_, plate->value, {"thickness", "margin"});
    if (b.ok()) {
      required_length(b, "thickness", stock.plate_thickness);
      double margin = 0;
      number(b, "margin", kLength, Bound::NonNegative, margin);
      stock.margin = {margin, margin, 0};
    }
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
  number(r, "density", kDensity, Bound::Positive, stock.density);
  number(r, "price_per_kg", kPricePerKg, Bound::NonNegative, stock.price_per_kg);
  machine_.raw_stocks.push_back(std::move(stock));
}

void MachineReader::read_margin(const Value& v, RawStock& stock) {
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

}  // namespace hybridctl::config::detail
