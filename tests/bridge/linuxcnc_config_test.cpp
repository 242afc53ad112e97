// The LinuxCNC sim configuration examples/linuxcnc/hybrid-3axis/ is the machine of
// examples/machines/hybrid-3axis.yaml: the same travel per axis, the tool table hybridctl
// writes for it, and the work offsets of its setups. (Whether LinuxCNC runs it is the
// end-to-end test's business, linuxcnc_bridge_test.py.)

#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "config/machine_loader.hpp"
#include "gcode/tool_table.hpp"

namespace hybridctl {
namespace {

const std::string kConfig = std::string(HYBRIDCTL_SOURCE_DIR) + "/examples/linuxcnc/hybrid-3axis/";

std::string read(const std::string& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in) << "cannot read " << path;
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// "[SECTION]KEY" -> value (the last one when repeated).
std::map<std::string, std::string> read_ini(const std::string& path) {
  std::map<std::string, std::string> out;
  std::istringstream in(read(path));
  std::string line, section;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (line[0] == '[') {
      section = line.substr(0, line.find(']') + 1);
      continue;
    }
    const auto eq = line.find('=');
    if (eq == std::string::npos) continue;
    auto trim = [](std::string s) {
      s.erase(0, s.find_first_not_of(" \t"));
      s.erase(s.find_last_not_of(" \t") + 1);
      return s;
    };
    out[section + trim(line.substr(0, eq))] = trim(line.substr(eq + 1));
  }
  return out;
}

const config::Machine& machine() {
  static const config::Machine m = config::load_machine(std::string(HYBRIDCTL_SOURCE_DIR) + "/examples/machines/hybrid-3axis.yaml");
  return m;
}

TEST(LinuxcncConfig, AxesHaveTheMachinesTravel) {
  const auto ini = read_ini(kConfig + "hybrid-3axis.ini");
  const std::map<std::string, const config::LinearAxis*> axes{
      {"X", &machine().envelope.x}, {"Y", &machine().envelope.y}, {"Z", &machine().envelope.z}};
  int joint = 0;
  for (const auto& [name, axis] : axes) {
    for (const std::string& section : {"[AXIS_" + name + "]", "[JOINT_" + std::to_string(joint++) + "]"}) {
      EXPECT_DOUBLE_EQ(std::stod(ini.at(section + "MIN_LIMIT")), axis->travel.min) << section;
      EXPECT_DOUBLE_EQ(std::stod(ini.at(section + "MAX_LIMIT")), axis->travel.max) << section;
    }
  }
  EXPECT_EQ(ini.at("[TRAJ]COORDINATES"), "X Y Z");
  EXPECT_EQ(ini.at("[TRAJ]LINEAR_UNITS"), "mm");
  EXPECT_EQ(ini.at("[DISPLAY]DISPLAY"), "linuxcncrsh") << "headless: no GUI on the machine's PC";
}

TEST(LinuxcncConfig, ToolTableIsTheOneHybridctlWritesForTheMachine) {
  const auto ini = read_ini(kConfig + "hybrid-3axis.ini");
  EXPECT_EQ(read(kConfig + ini.at("[EMCIO]TOOL_TABLE")), gcode::linuxcnc_tool_table(machine()));
}

TEST(LinuxcncConfig, WorkOffsetsAreTheSetupsWorkOrigins) {
  const auto ini = read_ini(kConfig + "hybrid-3axis.ini");
  std::map<int, double> parameters;
  std::istringstream in(read(kConfig + ini.at("[RS274NGC]PARAMETER_FILE")));
  int number = 0;
  double value = 0;
  while (in >> number >> value) parameters[number] = value;
  ASSERT_FALSE(machine().setups.empty());
  for (const config::Setup& s : machine().setups) {
    // G54 is parameters 5221-5223, G55 5241-5243, ... (LinuxCNC's numbered parameters).
    const int base = 5221 + 20 * (s.work_offset - 54);
    for (int a = 0; a < 3; ++a) {
      ASSERT_TRUE(parameters.count(base + a)) << "G" << s.work_offset << " parameter " << base + a;
      EXPECT_DOUBLE_EQ(parameters[base + a], s.work_origin[std::size_t(a)]) << "G" << s.work_offset << " axis " << a;
    }
  }
}

}  // namespace
}  // namespace hybridctl
