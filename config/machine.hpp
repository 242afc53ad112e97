#pragma once
// The machine model: what a hybrid (deposition + milling) machine can do, as plain values.
//
// Everything here is filled by config::parse_machine / load_machine from a machine file
// (docs/machine-file.md is the key-by-key reference). The default member values below are
// the documented defaults the loader applies when a key is absent. Units throughout:
// mm, s, degrees; feeds in mm/min (rotary: deg/min), accelerations in mm/s² (deg/s²),
// spindle speeds in rpm, volumes in mm³.

#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "config/primitive_kind.hpp"

namespace hybridctl::config {

/// A closed interval [min, max]; the loader guarantees min < max.
struct Range {
  double min = 0.0;
  double max = 0.0;

  double span() const { return max - min; }
  bool contains(double v) const { return v >= min && v <= max; }
};

/// One linear axis of the machine frame (Z up the spindle).
struct LinearAxis {
  Range travel;                         ///< mm, machine frame; required
  double max_feed = 5000.0;             ///< mm/min
  double max_acceleration = 500.0;      ///< mm/s²
};

/// One rotary axis (A about X, B about Y, C about Z).
struct RotaryAxis {
  char name = 'B';                      ///< 'A', 'B' or 'C'
  Range range;                          ///< degrees; required
  double max_feed = 3600.0;             ///< deg/min
  double max_acceleration = 360.0;      ///< deg/s²
};

/// Where the tool can go.
struct Envelope {
  LinearAxis x, y, z;
  std::vector<RotaryAxis> rotary;       ///< in A, B, C order; empty for a 3-axis machine

  const RotaryAxis* find_rotary(char axis_name) const {
    for (const auto& a : rotary)
      if (a.name == axis_name) return &a;
    return nullptr;
  }
};



/// What a head builds without support (docs/support.md): the layer rule's cone and how far
/// a bead may span air between two supports. The one definition of the rule the planner's
/// additive primitives and the simulator's deposition both apply
/// (instruments/support_rule.hpp).
struct SupportLimits {
  double max_overhang = 0.0;            ///< degrees from the build direction, 0 <= a < 90
  double max_bridge = 0.0;              ///< mm of air between two supports; 0: no bridging
};

enum class DepositionProcess { DedPowder, DedWire, WireArc, LaserWire };

/// Support limits of a process when the machine file gives none: powder DED 30 degrees,
/// wire-fed laser and ded-wire 20, wire-arc 15 (torch along the build direction); no
/// process bridges by default (a metal melt pool needs a substrate).
constexpr SupportLimits default_support(DepositionProcess p) {
  switch (p) {
    case DepositionProcess::DedPowder: return {30.0, 0.0};
    case DepositionProcess::DedWire: return {20.0, 0.0};
    case DepositionProcess::LaserWire: return {20.0, 0.0};
    case DepositionProcess::WireArc: return {15.0, 0.0};
  }
  return {0.0, 0.0};
}
/// Nozzle tip to programmed point when the machine file gives none: the powder focus of a
/// coaxial DED nozzle (10 mm), a wire-arc torch's contact tip to work distance (15 mm).
constexpr double default_standoff(DepositionProcess p) {
  return p == DepositionProcess::WireArc ? 15.0 : 10.0;
}

/// How close to its programmed surface a process lays material, mm either way, when the
/// machine file gives none (docs/machine-file.md cites the sources): powder DED 0.25,
/// laser wire 0.3, DED wire 0.5, wire-arc 1.0 (its waviness).
constexpr double default_accuracy(DepositionProcess p) {
  switch (p) {
    case DepositionProcess::DedPowder: return 0.25;
    case DepositionProcess::LaserWire: return 0.3;
    case DepositionProcess::DedWire: return 0.5;
    case DepositionProcess::WireArc: return 1.0;
  }
  return 0.25;
}

/// The stock an overfill deposit (O-AM) leaves beyond the design for a removal to finish,
/// mm, when the machine file gives none: shops deposit near-net plus 0.5-2 mm and mill it
/// off (docs/machine-file.md cites the sources): powder DED and laser wire 0.5, DED wire
/// 1.0, wire-arc 2.0.
constexpr double default_machining_allowance(DepositionProcess p) {
  switch (p) {
    case DepositionProcess::DedPowder: return 0.5;
    case DepositionProcess::LaserWire: return 0.5;
    case DepositionProcess::DedWire: return 1.0;
    case DepositionProcess::WireArc: return 2.0;
  }
  return 0.5;
}

/// What a head's deposit is made of, for what it costs (docs/costs.md).
struct DepositMaterial {
  double density = 7.9;                 ///< g/cm³ (316L stainless steel); > 0
  double price_per_kg = 0.0;            ///< money per kg bought, >= 0; default by process
  double efficiency = 1.0;              ///< fraction of the material fed that ends in the part, 0 < e <= 1; default by process
};

/// Material of a head when the machine file gives none: 316L, as gas-atomised powder for
/// powder DED (about 40 per kg; a coaxial nozzle catches about 70 % of the powder), as
/// welding wire for the wire processes (about 15 per kg; wire-arc loses about 5 % to
/// spatter, laser wire about 2 %). Placeholders from public list prices: set your own.
constexpr DepositMaterial default_material(DepositionProcess p) {
  switch (p) {
    case DepositionProcess::DedPowder: return {7.9, 40.0, 0.7};
    case DepositionProcess::DedWire: return {7.9, 15.0, 0.98};
    case DepositionProcess::LaserWire: return {7.9, 15.0, 0.98};
    case DepositionProcess::WireArc: return {7.9, 15.0, 0.95};
  }
  return {};
}

enum class BeadShape { Ellipsoid, Cylinder };

/// The cross-section one pass deposits: the head's minimum manufacturable neighbourhood.
struct Bead {
  BeadShape shape = BeadShape::Ellipsoid;
  double width = 0.0;                   ///< mm, > 0; required
  double height = 0.0;                  ///< mm, > 0; required
};

/// The non-cutting body around the deposition point: a cylinder whose lower end (the
/// nozzle tip) stands `standoff` above the programmed point (the bead's bottom).
struct Nozzle {
  double diameter = 0.0;                ///< mm, > 0
  double length = 0.0;                  ///< mm, > 0
  double standoff = 10.0;               ///< mm, > bead height; the loader's default is by process (default_standoff)
};

/// Machine codes that switch deposition. `power_template` contains "{power}", which the
/// post-processor replaces by `power`.
struct DepositionCodes {
  std::string on = "M64 P0";            ///< LinuxCNC: digital output 0 on
  std::string off = "M65 P0";           ///< LinuxCNC: digital output 0 off
  std::optional<std::string> power_template;  ///< e.g. "M68 E0 Q{power}"; none by default
  double power = 0.0;                   ///< the value substituted for {power}; >= 0
};

/// A deposition head.
struct AdditiveHead {
  std::string name;                     ///< unique among heads; required
  DepositionProcess process = DepositionProcess::DedPowder;  ///< required
  Bead bead;                            ///< required
  std::optional<Nozzle> nozzle;         ///< none: the head body is ignored for clearance
  SupportLimits support = default_support(DepositionProcess::DedPowder);  ///< default by process
  double layer_height = 0.0;            ///< mm, 0 < h <= bead.height; default 0.8 x bead.height
  double hatch_spacing = 0.0;           ///< mm, 0 < s <= bead.width; default 0.7 x bead.width
  double travel_clearance = 5.0;        ///< mm lifted for travel moves, >= 0
  /// mm, > 0: a face left as deposited lies within this of the modelled bead's surface,
  /// either way (its as-deposited accuracy); default by process (default_accuracy).
  double accuracy = default_accuracy(DepositionProcess::DedPowder);
  /// mm, >= 0: an overfill deposit (O-AM) covers the design by at least this everywhere,
  /// the stock a finishing removal takes off; default by process (default_machining_allowance).
  double machining_allowance = default_machining_allowance(DepositionProcess::DedPowder);
  double feed = 1000.0;                 ///< mm/min while depositing
  /// The T number that selects the head (`T.. M6`); default 100 + its index in `heads`;
  /// unique among heads and never a cutting tool's number.
  int tool_number = 0;
  DepositionCodes codes;
  double cost_per_mm3 = 1.0;            ///< cost factor per mm³ deposited, >= 0 (objective cost-factor)
  /// mm³ per minute of deposition, > 0; 0 in the model: not given (volume_rate()).
  double deposition_rate = 0.0;
  DepositMaterial material = default_material(DepositionProcess::DedPowder);  ///< default by process
  std::vector<PrimitiveKind> primitives = {PrimitiveKind::UAm, PrimitiveKind::OAm};

  bool offers(PrimitiveKind k) const {
    for (auto p : primitives)
      if (p == k) return true;
    return false;
  }
  /// mm³/min in force: the machine file's deposition_rate, else one layer of tracks at the
  /// hatch spacing laid at the feed.
  double volume_rate() const { return deposition_rate > 0 ? deposition_rate : layer_height * hatch_spacing * feed; }
};

/// The default head tool number is this plus the head's index in the machine file.
inline constexpr int kDefaultHeadToolNumberBase = 100;

/// Fractions that derive a head's layer height and hatch spacing from its bead when the
/// machine file does not give them.
inline constexpr double kDefaultLayerHeightFraction = 0.8;
inline constexpr double kDefaultHatchSpacingFraction = 0.7;

enum class ToolType { Flat, Ball, Bull };

/// A cylinder of the tool's non-cutting body (shank or holder).
struct ToolBody {
  double diameter = 0.0;                ///< mm, > 0
  double length = 0.0;                  ///< mm, > 0
};

/// A cutting tool (end mill) in the magazine.
struct CuttingTool {
  int number = 0;                       ///< T number, > 0, unique; required
  std::string name;                     ///< unique among tools; default "T<number>"
  ToolType type = ToolType::Flat;       ///< required
  double diameter = 0.0;                ///< mm, > 0; required
  double corner_radius = 0.0;           ///< mm; flat 0, ball diameter/2, bull 0 < r < diameter/2
  double flute_length = 0.0;            ///< mm, > 0; default 3 x diameter
  ToolBody shank;                       ///< default {diameter, 2 x diameter}
  ToolBody holder = {50.0, 60.0};       ///< default {50, 60}
  double spindle_speed = 10000.0;       ///< rpm, > 0
  double feed = 1000.0;                 ///< mm/min, > 0
  double plunge_feed = 300.0;           ///< mm/min, > 0
  /// mm/min of the finishing passes (walls, 3D faces), > 0; 0 in the model: not given (finishing_feed()).
  double finish_feed = 0.0;
  /// rpm of the finishing passes, > 0; 0 in the model: not given (finishing_spindle_speed()).
  double finish_spindle_speed = 0.0;
  double step_down = 0.0;               ///< mm, 0 < d <= flute_length; default 0.5 x diameter
  double step_over = 0.0;               ///< mm, 0 < s <= diameter; default 0.4 x diameter
  double cost_per_mm3 = 1.0;            ///< cost factor per mm³ removed, >= 0 (objective cost-factor)
  /// mm³ per minute of cutting, > 0; 0 in the model: not given (volume_rate()).
  double removal_rate = 0.0;
  double tool_price = 60.0;             ///< money per tool, >= 0: what wearing one out costs
  double tool_life = 90.0;              ///< minutes of cutting a tool lasts, > 0
  std::vector<PrimitiveKind> primitives = {PrimitiveKind::SmMax, PrimitiveKind::SmCons};

  /// Flute + shank + holder: how far the tool assembly reaches below the spindle nose.
  double stick_out() const { return flute_length + shank.length + holder.length; }
  /// mm³/min in force: the machine file's removal_rate, else a full step-down and
  /// step-over at the feed.
  double volume_rate() const { return removal_rate > 0 ? removal_rate : step_down * step_over * feed; }
  /// The finishing passes' feed in force: the machine file's finish_feed, else the feed.
  double finishing_feed() const { return finish_feed > 0 ? finish_feed : feed; }
  /// The finishing passes' spindle speed in force: finish_spindle_speed, else spindle_speed.
  double finishing_spindle_speed() const { return finish_spindle_speed > 0 ? finish_spindle_speed : spindle_speed; }
  bool offers(PrimitiveKind k) const {
    for (auto p : primitives)
      if (p == k) return true;
    return false;
  }
};

/// The direction the tool comes from, in the part frame ("+Z" = from above).
enum class Approach { PlusX, MinusX, PlusY, MinusY, PlusZ, MinusZ };

/// A rotary axis position held during a setup.
struct RotaryPosition {
  char axis = 'B';
  double degrees = 0.0;
};

/// One fixturing of the part.
struct Setup {
  std::string name;                     ///< unique; required
  std::string description;
  Approach approach = Approach::PlusZ;
  int work_offset = 54;                 ///< 54..59 for G54..G59
  /// Machine coordinates (mm) of the setup's work zero: the G54..G59 offset. Program
  /// (work-frame) coordinates + work_origin = machine coordinates, for rotary setups too.
  /// Default: X and Y at the middle of their travel, Z at the bottom of the Z travel.
  std::array<double, 3> work_origin = {0.0, 0.0, 0.0};
  bool manual_refixture = false;        ///< the operator re-clamps the part before this setup
  std::vector<RotaryPosition> rotary;   ///< axes not listed are not commanded

  std::optional<double> rotary_position(char axis) const {
    for (const auto& r : rotary)
      if (r.axis == axis) return r.degrees;
    return std::nullopt;
  }
};

enum class Axis { X, Y, Z };

/// A raw stock: a box around the part's bounding box, a round bar, or a plate of a given
/// thickness under the part (its underside at the part's lowest face, its sides `margin`
/// out from the part's on X and Y).
struct RawStock {
  enum class Kind { Box, RoundBar, Plate };
  std::string name;                     ///< unique; required
  Kind kind = Kind::Box;
  std::array<double, 3> margin = {1.0, 1.0, 1.0};  ///< box: mm added on each side in X, Y, Z, >= 0
  double bar_diameter = 0.0;            ///< round bar: mm, > 0
  double bar_length = 0.0;              ///< round bar: mm, > 0
  Axis bar_axis = Axis::Z;              ///< round bar: its axis in the part frame
  double plate_thickness = 0.0;         ///< plate: mm, > 0 (margin[0] and margin[1] hold its margins)
  double density = 7.9;                 ///< g/cm³ of the stock's material, > 0
  double price_per_kg = 6.0;            ///< money per kg of stock bought (316L bar or plate), >= 0
};

/// What the machine's time and the changes between actions cost (docs/costs.md). The
/// defaults are placeholders from public figures for a hybrid DED-milling cell: set the
/// shop's own.
struct Costs {
  std::string currency = "EUR";         ///< a label for money amounts
  double machine_rate = 120.0;          ///< money per hour of machine time, operator included, >= 0
  double tool_change = 8.0;             ///< s: an automatic tool change (or head to head), >= 0
  double head_switch = 60.0;            ///< s: between milling and deposition (head in, gas and powder settled), >= 0
  double setup_change = 10.0;           ///< s: to another setup's rotary position or work offset, >= 0
  double refixture = 15.0;              ///< min: the operator re-clamps the part (setups with manual_refixture), >= 0
};

/// What the plan search minimises: machine time, money (time x rate + material + tool
/// wear), or the dimensionless cost_per_mm3 factors and fixed_costs of older machine files.
enum class Objective { Time, Money, CostFactor };

/// Planner tunables and fixed costs.
struct Planning {
  double voxel_size = 0.5;              ///< mm, > 0
  double tolerance = 0.5;               ///< mm, >= 0
  double sliver_threshold = 1.0;        ///< mm³, >= 0: smaller atoms are noise
  int top_k = 5;                        ///< plans returned, >= 1
  double tool_change_cost = 0.0;        ///< >= 0
  double setup_change_cost = 0.0;       ///< >= 0
  double mode_switch_cost = 0.0;        ///< AM <-> SM, >= 0
  /// Default: money when the machine file has a `costs` section, else cost-factor (the
  /// dimensionless factors older machine files give).
  Objective objective = Objective::CostFactor;
};

enum class TransportKind { ModbusTcp, ModbusRtu, SocketCan, Socketcand };

/// A connection to the machine's controller, parsed from a URI:
///   modbus-tcp://HOST:PORT[?unit=N]
///   modbus-rtu:///dev/DEVICE[?baud=B&parity=N|E|O&unit=N]
///   socketcan://IFACE[?node=N]
///   socketcand://HOST:PORT/CHANNEL[?node=N]
struct Transport {
  std::string name;                     ///< the key in `transports`
  std::string uri;                      ///< as written
  TransportKind kind = TransportKind::ModbusTcp;
  std::string host;                     ///< modbus-tcp, socketcand
  int port = 0;                         ///< modbus-tcp, socketcand: 1..65535
  std::string device;                   ///< modbus-rtu: absolute path of the serial device
  int baud = 19200;                     ///< modbus-rtu
  char parity = 'E';                    ///< modbus-rtu: 'N', 'E' or 'O'
  int unit = 1;                         ///< modbus: unit (slave) id, TCP 0..255, RTU 1..247
  std::string interface_name;           ///< socketcan: network interface, e.g. "can0"
  std::string channel;                  ///< socketcand: bus name on the remote host
  int node = 1;                         ///< socketcan, socketcand: node id 1..127
};

enum class Dialect { Rs274ngc, Fanuc };

/// Overridable M codes. program_end defaults to M2 for rs274ngc and M30 for fanuc.
struct MCodes {
  std::string program_stop = "M0";
  std::string optional_stop = "M1";
  std::string program_end = "M2";
  std::string spindle_cw = "M3";
  std::string spindle_ccw = "M4";
  std::string spindle_stop = "M5";
  std::string tool_change = "M6";
  std::string coolant_on = "M8";
  std::string coolant_off = "M9";
};

struct GcodeSettings {
  Dialect dialect = Dialect::Rs274ngc;
  int program_number = 1000;            ///< fanuc O number, 1..9999
  MCodes m_codes;
};

/// The whole machine.
struct Machine {
  std::string name;                     ///< required
  std::string description;
  Envelope envelope;                    ///< required
  std::vector<AdditiveHead> heads;      ///< heads + tools: at least one in all
  std::vector<CuttingTool> tools;
  std::vector<Setup> setups;            ///< at least one
  std::vector<RawStock> raw_stocks = {RawStock{.name = "box"}};  ///< default: one box, margin 1 mm
  Planning planning;
  Costs costs;
  std::vector<Transport> transports;    ///< in file order
  GcodeSettings gcode;

  const CuttingTool* find_tool(int number) const {
    for (const auto& t : tools)
      if (t.number == number) return &t;
    return nullptr;
  }
  const AdditiveHead* find_head(std::string_view head_name) const {
    for (const auto& h : heads)
      if (h.name == head_name) return &h;
    return nullptr;
  }
  /// The head selected by T number `number`, if any.
  const AdditiveHead* find_head_by_tool(int number) const {
    for (const auto& h : heads)
      if (h.tool_number == number) return &h;
    return nullptr;
  }
  /// The first setup using work offset G`offset` (54..59); setups sharing an offset share
  /// its work_origin (the loader checks).
  const Setup* find_setup_by_work_offset(int offset) const {
    for (const auto& s : setups)
      if (s.work_offset == offset) return &s;
    return nullptr;
  }
  const Setup* find_setup(std::string_view setup_name) const {
    for (const auto& s : setups)
      if (s.name == setup_name) return &s;
    return nullptr;
  }
  const Transport* find_transport(std::string_view transport_name) const {
    for (const auto& t : transports)
      if (t.name == transport_name) return &t;
    return nullptr;
  }
};

constexpr std::string_view to_string(DepositionProcess p) {
  switch (p) {
    case DepositionProcess::DedPowder: return "ded-powder";
    case DepositionProcess::DedWire: return "ded-wire";
    case DepositionProcess::WireArc: return "wire-arc";
    case DepositionProcess::LaserWire: return "laser-wire";
  }
  return "?";
}
constexpr std::string_view to_string(BeadShape s) {
  return s == BeadShape::Ellipsoid ? "ellipsoid" : "cylinder";
}
constexpr std::string_view to_string(ToolType t) {
  switch (t) {
    case ToolType::Flat: return "flat";
    case ToolType::Ball: return "ball";
    case ToolType::Bull: return "bull";
  }
  return "?";
}
constexpr std::string_view to_string(Approach a) {
  switch (a) {
    case Approach::PlusX: return "+X";
    case Approach::MinusX: return "-X";
    case Approach::PlusY: return "+Y";
    case Approach::MinusY: return "-Y";
    case Approach::PlusZ: return "+Z";
    case Approach::MinusZ: return "-Z";
  }
  return "?";
}
constexpr std::string_view to_string(Objective o) {
  return o == Objective::Time ? "time" : o == Objective::Money ? "money" : "cost-factor";
}
constexpr std::string_view to_string(Axis a) { return a == Axis::X ? "X" : a == Axis::Y ? "Y" : "Z"; }
constexpr std::string_view to_string(TransportKind k) {
  switch (k) {
    case TransportKind::ModbusTcp: return "modbus-tcp";
    case TransportKind::ModbusRtu: return "modbus-rtu";
    case TransportKind::SocketCan: return "socketcan";
    case TransportKind::Socketcand: return "socketcand";
  }
  return "?";
}
constexpr std::string_view to_string(Dialect d) { return d == Dialect::Rs274ngc ? "rs274ngc" : "fanuc"; }

}  // namespace hybridctl::config
