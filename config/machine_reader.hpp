#pragma once
// Internal to the machine-file loader (machine_loader.cpp and the machine_reader*.cpp
// files); nothing else includes it. MachineReader reads one parsed YAML document into a
// Machine, section by section, reporting every problem through the sink:
//   machine_reader.cpp           the top level, shared readers, planning, transports, gcode
//   machine_reader_hardware.cpp  envelope, additive heads, cutting tools
//   machine_reader_setups.cpp    setups and raw stocks

#include <cstdio>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "common/number_text.hpp"
#include "config/diagnostic.hpp"
#include "config/machine.hpp"
#include "config/yaml_reader.hpp"

namespace hybridctl::config::detail {

inline std::string fmt(double v) { return shortest_number(v); }

inline std::string line_of(const YAML::Mark& m) { return std::to_string(m.is_null() ? 1 : m.line + 1); }

/// Reads a whole machine document into a Machine, reporting through the sink.
class MachineReader {
 public:
  explicit MachineReader(DiagnosticSink& sink) : sink_(sink) {}

  Machine load(const YAML::Node& root);

 private:
  template <class T>
  static void set(const std::optional<T>& value, T& target) {
    if (value) target = *value;
  }

  /// Sets `target` when `key` is present and valid; returns the value read, if any.
  std::optional<double> number(const MapReader& r, std::string_view key, Quantity q, Bound bound, double& target);
  /// A required positive length.
  std::optional<double> required_length(MapReader& r, std::string_view key, double& target);
  /// One line of G-code or M-code words, e.g. "M64 P0".
  std::optional<std::string> code_line(const Value& v);
  /// Reports a duplicate name; `seen` maps names to the line of their first use.
  void unique(std::map<std::string, YAML::Mark>& seen, const std::string& name, const Value& at,
              std::string_view what);
  std::vector<PrimitiveKind> primitives(const Value& v,
                                        const std::vector<std::pair<std::string_view, PrimitiveKind>>& choices,
                                        std::vector<PrimitiveKind> fallback);

  // envelope, heads, tools (machine_reader_hardware.cpp)
  void read_envelope(const Value& v);
  /// Returns whether the travel was read.
  bool read_linear_axis(const Value& v, LinearAxis& axis);
  void read_rotary_axis(const Value& v, char name);
  std::optional<std::size_t> read_heads(const Value& v);
  void read_head(const Value& v);
  void read_nozzle(const Value& v, AdditiveHead& head, bool bead_known);
  void read_support(const Value& v, SupportLimits& support);
  void read_material(const Value& v, DepositMaterial& material);
  void read_deposition_codes(const Value& v, DepositionCodes& codes);
  /// Head tool numbers are unique among heads and never a cutting tool's number.
  void check_head_tool_numbers();
  std::optional<std::size_t> read_tools(const Value& v);
  void read_tool(const Value& v);
  void read_tool_number_and_name(MapReader& r, CuttingTool& t);
  void read_corner_radius(MapReader& r, std::optional<ToolType> type, std::optional<double> diameter,
                          CuttingTool& t);
  void read_steps(const MapReader& r, bool flute_length_read, std::optional<double> diameter, CuttingTool& t);
  void read_tool_body(const Value& v, ToolBody& body);

  // setups, raw stocks (machine_reader_setups.cpp)
  void read_setups(const Value& v);
  void read_setup(const Value& v);
  void read_work_origin(const Value& v, Setup& s);
  void read_rotary_positions(const Value& v, Setup& s);
  void read_raw_stocks(const Value& v);
  void read_raw_stock(const Value& v);
  void read_margin(const Value& v, RawStock& stock);

  // planning, transports, G-code (machine_reader.cpp)
  void read_planning(const Value& v);
  void read_costs(const Value& v);
  void read_transports(const Value& v);
  void read_gcode(const Value& v);
  void read_m_codes(const Value& v, MCodes& codes);

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

}  // namespace hybridctl::config::detail
