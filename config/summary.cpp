#include "config/summary.hpp"

#include <algorithm>
#include <cstdio>

#include "common/number_text.hpp"

namespace hybridctl::config {

namespace {

std::string fmt(double v) { return shortest_number(v); }

std::string range(const Range& r) { return fmt(r.min) + ".." + fmt(r.max); }

std::string primitives(const std::vector<PrimitiveKind>& kinds) {
  std::string out;
  for (auto k : kinds) out += (out.empty() ? "" : "+") + std::string(to_string(k));
  return out;
}

/// Rows of "label   text", the labels padded to one column.
struct Table {
  std::size_t label_width;
  std::string text;

  void row(const std::string& label, const std::string& value) {
    std::string line = label;
    line.resize(std::max(label_width, label.size() + 1), ' ');
    text += line + value + "\n";
  }
  void item(const std::string& label, const std::string& value) { row("  " + label, value); }
};

}  // namespace

std::string summarize(const Machine& m) {
  constexpr std::size_t kMinLabelWidth = 12, kMaxLabelWidth = 28;
  std::size_t longest = 0;
  for (const auto& h : m.heads) longest = std::max(longest, h.name.size());
  for (const auto& s : m.setups) longest = std::max(longest, s.name.size());
  for (const auto& r : m.raw_stocks) longest = std::max(longest, r.name.size());
  for (const auto& t : m.transports) longest = std::max(longest, t.name.size());
  Table out{std::clamp(longest + 4, kMinLabelWidth, kMaxLabelWidth), {}};
  out.row("machine", m.name + (m.description.empty() ? "" : " — " + m.description));

  const Envelope& e = m.envelope;
  std::string envelope = "X " + range(e.x.travel) + "  Y " + range(e.y.travel) + "  Z " + range(e.z.travel) + " mm";
  for (const auto& a : e.rotary) envelope += "  " + std::string(1, a.name) + " " + range(a.range) + " deg";
  out.row("envelope", envelope);
  out.row("max feed", "X " + fmt(e.x.max_feed) + "  Y " + fmt(e.y.max_feed) + "  Z " + fmt(e.z.max_feed) +
                             " mm/min");

  out.row("heads", std::to_string(m.heads.size()));
  for (const auto& h : m.heads) {
    std::string text = "T" + std::to_string(h.tool_number) + ", " + std::string(to_string(h.process)) + ", bead " +
                       std::string(to_string(h.bead.shape)) + " " + fmt(h.bead.width) + " x " + fmt(h.bead.height) +
                       " mm, layer " + fmt(h.layer_height) + " mm, hatch " + fmt(h.hatch_spacing) + " mm, feed " +
                       fmt(h.feed) + " mm/min, " + fmt(h.volume_rate()) + " mm³/min, " + primitives(h.primitives);
    text += ", overhang <= " + fmt(h.support.max_overhang) + " deg, " +
            (h.support.max_bridge > 0 ? "bridges <= " + fmt(h.support.max_bridge) + " mm" : std::string("no bridging"));
    text += ", as deposited within " + fmt(h.accuracy) + " mm, machining allowance " + fmt(h.machining_allowance) + " mm";
    if (h.nozzle)
      text += ", nozzle ø" + fmt(h.nozzle->diameter) + " x " + fmt(h.nozzle->length) + " mm at " +
              fmt(h.nozzle->standoff) + " mm standoff";
    out.item(h.name, text);
  }

  out.row("tools", std::to_string(m.tools.size()));
  for (const auto& t : m.tools) {
    std::string text = std::string(to_string(t.type)) + " ø" + fmt(t.diameter) + " mm";
    if (t.type == ToolType::Bull) text += " r" + fmt(t.corner_radius);
    if (t.name != "T" + std::to_string(t.number)) text += " \"" + t.name + "\"";
    text += ", flutes " + fmt(t.flute_length) + " mm, stick-out " + fmt(t.stick_out()) + " mm, " +
            fmt(t.spindle_speed) + " rpm" +
            (t.finish_spindle_speed > 0 ? " (finishing " + fmt(t.finish_spindle_speed) + ")" : std::string()) +
            ", feed " + fmt(t.feed) + " mm/min" +
            (t.finish_feed > 0 ? " (finishing " + fmt(t.finish_feed) + ")" : std::string()) + ", " + fmt(t.volume_rate()) + " mm³/min, " +
            primitives(t.primitives);
    out.item("T" + std::to_string(t.number), text);
  }

  out.row("setups", std::to_string(m.setups.size()));
  for (const auto& s : m.setups) {
    std::string text = "approach " + std::string(to_string(s.approach)) + ", G" + std::to_string(s.work_offset);
    for (const auto& r : s.rotary) text += ", " + std::string(1, r.axis) + " " + fmt(r.degrees) + " deg";
    text += ", work zero at X" + fmt(s.work_origin[0]) + " Y" + fmt(s.work_origin[1]) + " Z" + fmt(s.work_origin[2]);
    if (s.manual_refixture) text += ", manual refixture";
    out.item(s.name, text);
  }

  out.row("raw stocks", std::to_string(m.raw_stocks.size()));
  for (const auto& r : m.raw_stocks) {
    if (r.kind == RawStock::Kind::Box)
      out.item(r.name, "box, margin " + fmt(r.margin[0]) + " x " + fmt(r.margin[1]) + " x " + fmt(r.margin[2]) +
                              " mm around the part");
    else if (r.kind == RawStock::Kind::Plate)
      out.item(r.name, "plate " + fmt(r.plate_thickness) + " mm thick under the part, margin " + fmt(r.margin[0]) +
                              " mm on X and Y");
    else
      out.item(r.name, "round bar ø" + fmt(r.bar_diameter) + " x " + fmt(r.bar_length) + " mm along " +
                              std::string(to_string(r.bar_axis)));
  }

  out.row("transports", std::to_string(m.transports.size()));
  for (const auto& t : m.transports) out.item(t.name, t.uri);

  out.row("gcode", std::string(to_string(m.gcode.dialect)) +
                          (m.gcode.dialect == Dialect::Fanuc ? ", program O" + std::to_string(m.gcode.program_number)
                                                             : std::string()) +
                          ", program end " + m.gcode.m_codes.program_end);
  const Planning& p = m.planning;
  out.row("planning", "voxel " + fmt(p.voxel_size) + " mm, tolerance " + fmt(p.tolerance) + " mm, sliver " +
                             fmt(p.sliver_threshold) + " mm³, top " + std::to_string(p.top_k) + " plans, by " +
                             std::string(to_string(p.objective)));
  const Costs& c = m.costs;
  out.row("costs", fmt(c.machine_rate) + " " + c.currency + "/h, tool change " + fmt(c.tool_change) + " s, head switch " +
                          fmt(c.head_switch) + " s, setup change " + fmt(c.setup_change) + " s, refixture " +
                          fmt(c.refixture) + " min");
  return out.text;
}

}  // namespace hybridctl::config#include "common/number_text.hpp"

