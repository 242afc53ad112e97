// Fuzz target: the G-code parser and modal interpreter (gcode/parser.hpp,
// gcode/interpreter.hpp) line by line, as the simulator feeds them, and `hybridctl gcode
// check` (gcode/check.hpp) on the whole text, for the two example machines
// (examples/machines: hybrid-3axis, RS274NGC; multitask-b-axis, Fanuc-style, with a B axis).
//
// Input: byte 0 picks the machine (bit 0) and whether check_program runs too (bit 1; the
// seeds use the characters 0 to 3); the rest is the program text.
// Contract: execute_line throws GcodeError (and nothing else) naming the line, and leaves
// the modal state as it was; check_program never throws for bad G-code.

#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "config/machine_loader.hpp"
#include "fuzz/fuzz_check.hpp"
#include "gcode/check.hpp"
#include "gcode/interpreter.hpp"
#include "gcode/parser.hpp"

namespace config = hybridctl::config;
namespace gcode = hybridctl::gcode;

namespace {

std::vector<config::Machine>* machines = nullptr;

bool same_bits(double a, double b) { return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b); }
bool same_bits(const gcode::Vec3& a, const gcode::Vec3& b) {
  return same_bits(a.x, b.x) && same_bits(a.y, b.y) && same_bits(a.z, b.z);
}

// Every field of the modal state, doubles compared bit for bit (a NaN equals itself).
bool same_state(const gcode::ModalState& a, const gcode::ModalState& b) {
  return same_bits(a.position, b.position) && same_bits(a.rotary.a, b.rotary.a) && same_bits(a.rotary.b, b.rotary.b) &&
         same_bits(a.rotary.c, b.rotary.c) && a.motion == b.motion && a.motion_active == b.motion_active &&
         a.plane == b.plane && a.absolute == b.absolute && a.arc_absolute == b.arc_absolute && a.inches == b.inches &&
         a.work_offset == b.work_offset && same_bits(a.offset, b.offset) && same_bits(a.feed, b.feed) &&
         same_bits(a.spindle_speed, b.spindle_speed) && a.spindle == b.spindle && a.selected_tool == b.selected_tool &&
         a.tool == b.tool && a.tool_length_offset == b.tool_length_offset && a.coolant == b.coolant &&
         a.deposition == b.deposition && a.ended == b.ended;
}

bool finite(const gcode::Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  machines = new std::vector<config::Machine>;
  for (const char* file : {"hybrid-3axis.yaml", "multitask-b-axis.yaml"})
    machines->push_back(config::load_machine(std::string(HYBRIDCTL_SOURCE_DIR "/examples/machines/") + file));
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const config::Machine& machine = (*machines)[data[0] & 1u];
  const bool run_check = (data[0] & 2u) != 0;
  const std::string_view text(reinterpret_cast<const char*>(data + 1), size - 1);
  const std::string name = "fuzz.ngc";

  gcode::Interpreter interpreter(machine, name);
  gcode::for_each_line(text, [&](std::string_view line, int number) {
    const gcode::ModalState before = interpreter.state();
    try {
      const gcode::LineResult& result = interpreter.execute_line(line, number);
      for (const gcode::Motion& m : result.motions) {
        FUZZ_CHECK(m.line == number, "a motion names its line");
        FUZZ_CHECK(finite(m.to_machine) && finite(m.to_work), "a motion ends at a finite position");
      }
      for (const gcode::Event& e : result.events) FUZZ_CHECK(e.line == number, "an event names its line");
    } catch (const gcode::GcodeError& e) {
      FUZZ_CHECK(e.line() == number, "a G-code error names its line");
      FUZZ_CHECK(e.column() >= 1, "a G-code error names a column");
      FUZZ_CHECK(std::string_view(e.what()).starts_with(name + ":"), "a G-code error names the file");
      FUZZ_CHECK(same_state(before, interpreter.state()), "a refused line leaves the modal state as it was");
    }
  });

  if (run_check) {
    const gcode::CheckReport report = gcode::check_program(text, machine, name);
    FUZZ_CHECK(std::isfinite(report.time.total) && report.time.total >= 0, "the cycle time is a finite duration");
    (void)report.str();
  }
  return 0;
}
