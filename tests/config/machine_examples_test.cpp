// The bundled example machines load without diagnostics and mean what their comments say;
// a minimal machine file gets the documented defaults; lookups and the summary work.

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

#include "config/machine_loader.hpp"

namespace {

using namespace hybridctl::config;

Machine example(const std::string& name) {
  return load_machine(std::string(HYBRIDCTL_SOURCE_DIR) + "/examples/machines/" + name);
}

TEST(MachineExamples, Hybrid3AxisLoads) {
  Machine m;
  ASSERT_NO_THROW(m = example("hybrid-3axis.yaml"));
  EXPECT_EQ(m.name, "hybrid-3axis");
  EXPECT_EQ(m.envelope.x.travel.max, 400.0);
  EXPECT_EQ(m.envelope.z.travel.span(), 300.0);
  EXPECT_EQ(m.envelope.z.max_feed, 8000.0);
  EXPECT_TRUE(m.envelope.rotary.empty());

  ASSERT_EQ(m.heads.size(), 1u);
  const AdditiveHead* ded = m.find_head("ded");
  ASSERT_NE(ded, nullptr);
  EXPECT_EQ(ded->process, DepositionProcess::DedPowder);
  EXPECT_EQ(ded->bead.shape, BeadShape::Ellipsoid);
  EXPECT_EQ(ded->bead.width, 1.5);
  EXPECT_EQ(ded->bead.height, 0.75);
  EXPECT_EQ(ded->layer_height, 0.6);
  EXPECT_EQ(ded->hatch_spacing, 1.05);
  ASSERT_TRUE(ded->nozzle.has_value());
  EXPECT_EQ(ded->nozzle->length, 60.0);
  EXPECT_EQ(ded->nozzle->standoff, 10.0);
  EXPECT_EQ(ded->support.max_overhang, 30.0);
  EXPECT_EQ(ded->support.max_bridge, 0.0);
  EXPECT_EQ(ded->codes.on, "M64 P0");
  EXPECT_EQ(ded->codes.off, "M65 P0");
  EXPECT_EQ(ded->codes.power_template, "M68 E0 Q{power}");
  EXPECT_EQ(ded->codes.power, 800.0);
  EXPECT_TRUE(ded->offers(PrimitiveKind::UAm));
  EXPECT_TRUE(ded->offers(PrimitiveKind::OAm));
  EXPECT_EQ(m.find_head("arc"), nullptr);

  ASSERT_EQ(m.tools.size(), 3u);
  const CuttingTool* t2 = m.find_tool(2);
  ASSERT_NE(t2, nullptr);
  EXPECT_EQ(t2->type, ToolType::Ball);
  EXPECT_EQ(t2->corner_radius, 3.0);  // defaulted to diameter/2
  EXPECT_TRUE(t2->offers(PrimitiveKind::SmMax));
  EXPECT_FALSE(t2->offers(PrimitiveKind::SmCons));
  const CuttingTool* t1 = m.find_tool(1);
  ASSERT_NE(t1, nullptr);
  EXPECT_EQ(t1->corner_radius, 0.0);
  EXPECT_EQ(t1->stick_out(), 22.0 + 50.0 + 60.0);
  EXPECT_EQ(t1->holder.diameter, 42.0);
  EXPECT_EQ(m.find_tool(3)->diameter, 3.0);
  EXPECT_EQ(m.find_tool(4), nullptr);

  ASSERT_EQ(m.setups.size(), 2u);
  const hybridctl::config::Setup* bottom = m.find_setup("bottom");
  ASSERT_NE(bottom, nullptr);
  EXPECT_EQ(bottom->approach, Approach::MinusZ);
  EXPECT_EQ(bottom->work_offset, 55);
  EXPECT_TRUE(bottom->manual_refixture);
  EXPECT_FALSE(m.find_setup("top")->manual_refixture);

  ASSERT_EQ(m.raw_stocks.size(), 2u);
  EXPECT_EQ(m.raw_stocks[0].kind, RawStock::Kind::Box);
  EXPECT_EQ(m.raw_stocks[0].margin[2], 3.0);
  EXPECT_EQ(m.raw_stocks[1].kind, RawStock::Kind::RoundBar);
  EXPECT_EQ(m.raw_stocks[1].bar_diameter, 90.0);
  EXPECT_EQ(m.raw_stocks[1].bar_axis, Axis::Z);

  EXPECT_EQ(m.planning.mode_switch_cost, 50.0);
  ASSERT_EQ(m.transports.size(), 3u);
  const Transport* sim = m.find_transport("sim");
  ASSERT_NE(sim, nullptr);
  EXPECT_EQ(sim->kind, TransportKind::ModbusTcp);
  EXPECT_EQ(sim->host, "127.0.0.1");
  EXPECT_EQ(sim->port, 1502);
  const Transport* rtu = m.find_transport("cell-rtu");
  ASSERT_NE(rtu, nullptr);
  EXPECT_EQ(rtu->device, "/dev/ttyUSB0");
  EXPECT_EQ(rtu->baud, 115200);
  EXPECT_EQ(rtu->parity, 'N');
  const Transport* can = m.find_transport("can");
  ASSERT_NE(can, nullptr);
  EXPECT_EQ(can->kind, TransportKind::Socketcand);
  EXPECT_EQ(can->port, 29536);
  EXPECT_EQ(can->channel, "can0");

  EXPECT_EQ(m.gcode.dialect, Dialect::Rs274ngc);
  EXPECT_EQ(m.gcode.m_codes.program_end, "M2");
}

TEST(MachineExamples, MultitaskBAxisLoads) {
  Machine m;
  ASSERT_NO_THROW(m = example("multitask-b-axis.yaml"));
  const RotaryAxis* b = m.envelope.find_rotary('B');
  ASSERT_NE(b, nullptr);
  EXPECT_EQ(b->range.min, -120.0);
  EXPECT_EQ(b->range.max, 120.0);
  EXPECT_EQ(m.envelope.find_rotary('A'), nullptr);

  ASSERT_EQ(m.heads.size(), 2u);
  EXPECT_EQ(m.find_head("arc")->process, DepositionProcess::WireArc);
  EXPECT_EQ(m.find_head("arc")->bead.shape, BeadShape::Cylinder);
  EXPECT_FALSE(m.find_head("arc")->offers(PrimitiveKind::UAm));
  const AdditiveHead* ded = m.find_head("ded");
  EXPECT_DOUBLE_EQ(ded->layer_height, 0.8 * 0.5);   // derived from the bead
  EXPECT_DOUBLE_EQ(ded->hatch_spacing, 0.7 * 1.2);
  EXPECT_EQ(ded->travel_clearance, 5.0);

  const CuttingTool* bull = m.find_tool(2);
  ASSERT_NE(bull, nullptr);
  EXPECT_EQ(bull->type, ToolType::Bull);
  EXPECT_EQ(bull->corner_radius, 1.0);
  const CuttingTool* t12 = m.find_tool(12);  // all defaults but the diameter
  ASSERT_NE(t12, nullptr);
  EXPECT_EQ(t12->flute_length, 36.0);
  EXPECT_EQ(t12->shank.diameter, 12.0);
  EXPECT_EQ(t12->shank.length, 24.0);
  EXPECT_EQ(t12->holder.diameter, 50.0);
  EXPECT_EQ(t12->holder.length, 60.0);
  EXPECT_EQ(t12->step_down, 6.0);
  EXPECT_DOUBLE_EQ(t12->step_over, 4.8);
  EXPECT_EQ(t12->spindle_speed, 10000.0);

  ASSERT_EQ(m.setups.size(), 4u);
  const hybridctl::config::Setup* side = m.find_setup("side-x-plus");
  ASSERT_NE(side, nullptr);
  EXPECT_EQ(side->approach, Approach::PlusX);
  EXPECT_EQ(side->rotary_position('B'), 90.0);
  EXPECT_EQ(m.find_setup("side-x-minus")->rotary_position('B'), -90.0);
  EXPECT_EQ(m.find_setup("side-y-plus")->approach, Approach::PlusY);
  EXPECT_FALSE(m.find_setup("top")->rotary_position('A').has_value());

  EXPECT_EQ(m.gcode.dialect, Dialect::Fanuc);
  EXPECT_EQ(m.gcode.program_number, 2000);
  EXPECT_EQ(m.gcode.m_codes.program_end, "M30");   // fanuc default
  EXPECT_EQ(m.gcode.m_codes.spindle_cw, "M203");   // overridden
  EXPECT_EQ(m.gcode.m_codes.tool_change, "M6");    // default
  EXPECT_EQ(m.planning.sliver_threshold, 1.0);     // default
  EXPECT_EQ(m.planning.top_k, 3);
}

TEST(MachineDefaults, AMinimalMachineGetsTheDocumentedDefaults) {
  const Machine m = parse_machine(
      "name: minimal\n"
      "envelope: {X: {travel: [0, 100]}, Y: {travel: [0, 100]}, Z: {travel: [0, 100]}}\n"
      "heads: [{name: h, process: ded-wire, bead: {width: 2, height: 1}}]\n"
      "setups: [{name: s}]\n",
      "minimal.yaml");
  EXPECT_EQ(m.description, "");
  EXPECT_EQ(m.envelope.x.max_feed, 5000.0);
  EXPECT_EQ(m.envelope.x.max_acceleration, 500.0);
  const AdditiveHead& h = m.heads.at(0);
  EXPECT_DOUBLE_EQ(h.layer_height, 0.8);
  EXPECT_DOUBLE_EQ(h.hatch_spacing, 1.4);
  EXPECT_FALSE(h.nozzle.has_value());
  EXPECT_EQ(h.codes.on, "M64 P0");
  EXPECT_EQ(h.codes.off, "M65 P0");
  EXPECT_FALSE(h.codes.power_template.has_value());
  EXPECT_EQ(h.feed, 1000.0);
  EXPECT_EQ(h.cost_per_mm3, 1.0);
  EXPECT_TRUE(m.tools.empty());
  const hybridctl::config::Setup& s = m.setups.at(0);
  EXPECT_EQ(s.approach, Approach::PlusZ);
  EXPECT_EQ(s.work_offset, 54);
  EXPECT_FALSE(s.manual_refixture);
  ASSERT_EQ(m.raw_stocks.size(), 1u);
  EXPECT_EQ(m.raw_stocks[0].name, "box");
  EXPECT_EQ(m.raw_stocks[0].kind, RawStock::Kind::Box);
  EXPECT_EQ(m.raw_stocks[0].margin[0], 1.0);
  EXPECT_EQ(m.planning.voxel_size, 0.5);
  EXPECT_EQ(m.planning.tolerance, 0.5);
  EXPECT_EQ(m.planning.sliver_threshold, 1.0);
  EXPECT_EQ(m.planning.top_k, 5);
  EXPECT_EQ(m.planning.tool_change_cost, 0.0);
  EXPECT_EQ(m.planning.setup_change_cost, 0.0);
  EXPECT_EQ(m.planning.mode_switch_cost, 0.0);
  EXPECT_TRUE(m.transports.empty());
  EXPECT_EQ(m.gcode.dialect, Dialect::Rs274ngc);
  EXPECT_EQ(m.gcode.program_number, 1000);
  const MCodes& c = m.gcode.m_codes;
  EXPECT_EQ(c.program_stop + c.optional_stop + c.program_end + c.spindle_cw + c.spindle_ccw + c.spindle_stop +
                c.tool_change + c.coolant_on + c.coolant_off,
            "M0M1M2M3M4M5M6M8M9");
}

TEST(MachineDefaults, ToolDefaultsFollowTheTypeAndDiameter) {
  const Machine m = parse_machine(
      "name: t\n"
      "envelope: {X: {travel: [0, 100]}, Y: {travel: [0, 100]}, Z: {travel: [0, 200]}}\n"
      "tools:\n"
      "  - {number: 5, type: ball, diameter: 8}\n"
      "  - {number: 6, type: flat, diameter: 4, name: small, finish_feed: 450, finish_spindle_speed: 14000}\n"
      "setups: [{name: s}]\n",
      "t.yaml");
  const CuttingTool& ball = *m.find_tool(5);
  EXPECT_EQ(ball.name, "T5");
  EXPECT_EQ(ball.corner_radius, 4.0);
  EXPECT_EQ(ball.flute_length, 24.0);
  EXPECT_EQ(ball.shank.diameter, 8.0);
  EXPECT_EQ(ball.shank.length, 16.0);
  EXPECT_EQ(ball.step_down, 4.0);
  EXPECT_DOUBLE_EQ(ball.step_over, 3.2);
  EXPECT_EQ(ball.feed, 1000.0);
  EXPECT_EQ(ball.plunge_feed, 300.0);
  EXPECT_EQ(ball.finishing_feed(), 1000.0) << "the feed, when no finish_feed is given";
  EXPECT_EQ(ball.finishing_spindle_speed(), ball.spindle_speed) << "the spindle speed, when none is given";
  EXPECT_EQ(ball.cost_per_mm3, 1.0);
  EXPECT_TRUE(ball.offers(PrimitiveKind::SmMax));
  EXPECT_TRUE(ball.offers(PrimitiveKind::SmCons));
  EXPECT_EQ(m.find_tool(6)->name, "small");
  EXPECT_EQ(m.find_tool(6)->corner_radius, 0.0);
  EXPECT_EQ(m.find_tool(6)->finishing_feed(), 450.0);
  EXPECT_EQ(m.find_tool(6)->finishing_spindle_speed(), 14000.0);
}

TEST(MachineSummary, NamesEverySection) {
  const std::string s = summarize(example("multitask-b-axis.yaml"));
  for (const char* word : {"multitask-b-axis", "X 0..600", "B -120..120 deg", "wire-arc", "T2", "bull ø10 mm r1",
                           "side-x-plus", "approach +X, G55, B 90 deg", "round bar ø100", "controller",
                           "modbus-tcp://192.168.10.20:502?unit=1", "fanuc", "O2000"})
    EXPECT_NE(s.find(word), std::string::npos) << "'" << word << "' missing in:\n" << s;
  const std::string t = summarize(example("hybrid-3axis.yaml"));
  for (const char* word : {"manual refixture", "rs274ngc", "socketcand://127.0.0.1:29536/can0", "ded-powder"})
    EXPECT_NE(t.find(word), std::string::npos) << "'" << word << "' missing in:\n" << t;
}

}  // namespace

namespace {

TEST(MachineDocs, TheShortExampleInTheReferenceLoads) {
  std::ifstream in(std::string(HYBRIDCTL_SOURCE_DIR) + "/docs/machine-file.md");
  std::stringstream buffer;
  buffer << in.rdbuf();
  const std::string doc = buffer.str();
  const auto begin = doc.find("```yaml\n");
  ASSERT_NE(begin, std::string::npos);
  const auto end = doc.find("```", begin + 8);
  ASSERT_NE(end, std::string::npos);
  const hybridctl::config::Machine m =
      hybridctl::config::parse_machine(doc.substr(begin + 8, end - begin - 8), "machine-file.md");
  EXPECT_EQ(m.name, "small-hybrid");
  EXPECT_EQ(m.heads.size() + m.tools.size(), 2u);
}

}  // namespace
