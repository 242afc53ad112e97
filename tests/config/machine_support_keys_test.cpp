// A head's support keys (what it builds without support), its nozzle's stand-off, its
// as-deposited accuracy and machining allowance: defaults by process when absent (old machine files keep loading), values as written,
// and every bad value reported at its place.

#include <gtest/gtest.h>

#include <string>

#include "config/machine_loader.hpp"
#include "config/summary.hpp"

namespace {

using namespace hybridctl::config;

std::string machine_with_head(const std::string& head) {
  return "name: m\n"                                  // 1
         "envelope: {X: {travel: [0, 100]}, Y: {travel: [0, 100]}, Z: {travel: [0, 100]}}\n"  // 2
         "setups: [{name: top}]\n"                    // 3
         "heads:\n"                                   // 4
         "  - " + head + "\n";                        // 5
}

std::string errors_of(const std::string& yaml) {
  try {
    parse_machine(yaml, "m.yaml");
  } catch (const MachineFileError& e) {
    std::string out;
    for (const auto& d : e.diagnostics()) out += d.str() + "\n";
    return out;
  }
  return "";
}

TEST(MachineSupportKeys, AbsentKeysTakeTheProcessDefaults) {
  struct Case {
    const char* process;
    double overhang, standoff, accuracy, allowance;
  };
  for (const Case c : {Case{"ded-powder", 30, 10, 0.25, 0.5}, Case{"ded-wire", 20, 10, 0.5, 1.0},
                       Case{"laser-wire", 20, 10, 0.3, 0.5}, Case{"wire-arc", 15, 15, 1.0, 2.0}}) {
    SCOPED_TRACE(c.process);
    const Machine m = parse_machine(machine_with_head(std::string("{name: h, process: ") + c.process +
                                                      ", bead: {width: 2, height: 1}, nozzle: {diameter: 20, length: 60}}"),
                                    "m.yaml");
    const AdditiveHead& h = m.heads.at(0);
    EXPECT_EQ(h.support.max_overhang, c.overhang);
    EXPECT_EQ(h.support.max_bridge, 0);
    ASSERT_TRUE(h.nozzle.has_value());
    EXPECT_EQ(h.nozzle->standoff, c.standoff);
    EXPECT_EQ(h.accuracy, c.accuracy);
    EXPECT_EQ(h.machining_allowance, c.allowance);
  }
}

TEST(MachineSupportKeys, GivenValuesAreKeptAndShownInTheSummary) {
  const Machine m = parse_machine(
      machine_with_head("{name: ded, process: ded-powder, bead: {width: 1.5, height: 0.75}, "
                        "support: {max_overhang: 45, max_bridge: 3}, nozzle: {diameter: 20, length: 60, standoff: 8}, "
                        "accuracy: 0.2, machining_allowance: 0.8}"),
      "m.yaml");
  const AdditiveHead& h = m.heads.at(0);
  EXPECT_EQ(h.support.max_overhang, 45);
  EXPECT_EQ(h.support.max_bridge, 3);
  EXPECT_EQ(h.nozzle->standoff, 8);
  EXPECT_EQ(h.machining_allowance, 0.8);
  const std::string text = summarize(m);
  EXPECT_NE(text.find("as deposited within 0.2 mm, machining allowance 0.8 mm"), std::string::npos) << text;
  EXPECT_NE(text.find("overhang <= 45 deg, bridges <= 3 mm"), std::string::npos) << text;
  EXPECT_NE(text.find("nozzle ø20 x 60 mm at 8 mm standoff"), std::string::npos) << text;
  // Only one key given: the other keeps the process's default.
  const Machine one = parse_machine(
      machine_with_head("{name: arc, process: wire-arc, bead: {width: 6, height: 2}, support: {max_bridge: 4}}"), "m.yaml");
  EXPECT_EQ(one.heads.at(0).support.max_overhang, 15);
  EXPECT_EQ(one.heads.at(0).support.max_bridge, 4);
  EXPECT_NE(summarize(one).find("overhang <= 15 deg, bridges <= 4 mm"), std::string::npos);
}

TEST(MachineSupportKeys, BadValuesAreReportedAtTheirPlace) {
  const std::string bead = "name: h, process: ded-powder, bead: {width: 2, height: 1}, ";
  EXPECT_EQ(errors_of(machine_with_head("{" + bead + "support: {max_overhang: 90}}")),
            "m.yaml:5:89: heads[0].support.max_overhang: expected an angle from the build direction below 90 degrees "
            "(90 would be a horizontal shelf over air), got 90\n");
  EXPECT_NE(errors_of(machine_with_head("{" + bead + "support: {max_overhang: -5}}")).find("heads[0].support.max_overhang"),
            std::string::npos);
  EXPECT_NE(errors_of(machine_with_head("{" + bead + "support: {max_bridge: -1}}")).find("m.yaml:5:87: heads[0].support.max_bridge"),
            std::string::npos);
  EXPECT_NE(errors_of(machine_with_head("{" + bead + "support: {max_overhang: 30, bridge: 2}}")).find("unknown key 'bridge'"),
            std::string::npos);
  EXPECT_NE(errors_of(machine_with_head("{" + bead + "machining_allowance: -0.5}")).find("heads[0].machining_allowance"),
            std::string::npos);
  // The nozzle tip must clear the bead it lays.
  EXPECT_EQ(errors_of(machine_with_head("{" + bead + "nozzle: {diameter: 20, length: 60, standoff: 1}}")),
            "m.yaml:5:110: heads[0].nozzle.standoff: expected more than the bead height 1 mm (the nozzle tip must clear "
            "the bead it lays), got 1\n");
  const std::string tall = "name: h, process: ded-powder, bead: {width: 20, height: 12}, ";
  EXPECT_NE(errors_of(machine_with_head("{" + tall + "nozzle: {diameter: 20, length: 60}}"))
                .find("the default standoff 10 mm of ded-powder does not clear the bead height 12 mm"),
            std::string::npos);
}

}  // namespace
