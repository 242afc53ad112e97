// Fuzz target: the machine-file loader (config/machine_loader.hpp: parse_machine, the
// in-memory form of load_machine) on arbitrary text, and the summary `hybridctl machine
// check` prints for a machine that loads.
// Contract: parse_machine throws config::MachineFileError and nothing else; its
// diagnostics name the file, at most 101 of them (100 and a "more" line), each with a
// message.

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "config/machine_loader.hpp"
#include "config/summary.hpp"
#include "fuzz/fuzz_check.hpp"

namespace config = hybridctl::config;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const std::string name = "fuzz.yaml";
  config::Machine machine;
  try {
    machine = config::parse_machine(text, name);
  } catch (const config::MachineFileError& e) {
    FUZZ_CHECK(!e.diagnostics().empty(), "a refused machine file has at least one diagnostic");
    FUZZ_CHECK(e.diagnostics().size() <= 101, "at most 100 diagnostics and a summary line");
    for (const config::Diagnostic& d : e.diagnostics()) {
      FUZZ_CHECK(d.file == name, "every diagnostic names the file");
      FUZZ_CHECK(!d.message.empty(), "every diagnostic says what is wrong");
      FUZZ_CHECK(d.line >= 0 && d.column >= 0, "places are 1-based, or 0 for the whole file");
    }
    return 0;
  }
  FUZZ_CHECK(!machine.name.empty(), "a machine that loads has a name");
  const std::string summary = config::summarize(machine);
  FUZZ_CHECK(!summary.empty() && summary.back() == '\n', "the summary is whole lines");
  return 0;
}
