#pragma once
// Internal to the interpreter (interpreter.cpp, interpreter_modal.cpp,
// interpreter_motion.cpp); nothing else includes it. One block's execution as a sequence
// of steps, each a member function of BlockExecution, called in the order that
// Interpreter::run documents.

#include <array>
#include <cstdint>
#include <string>

#include "gcode/interpreter.hpp"

namespace hybridctl::gcode {

namespace detail {

/// Whether a T, H, P or E value is a whole number from 0 to 99999 (and so fits an int).
bool number_word(double v);
/// A number for a message: at most 4 decimals, no trailing zeros.
std::string fmt(double v);

constexpr std::uint32_t bit(char letter) { return 1u << (letter - 'A'); }
constexpr std::uint32_t kAxisLetters = bit('X') | bit('Y') | bit('Z') | bit('A') | bit('B') | bit('C');
constexpr std::uint32_t kArcLetters = bit('I') | bit('J') | bit('K') | bit('R');

}  // namespace detail

/// One block's execution: the interpreter, the block, the state it changes, and what the
/// steps learn on the way for later steps (the G codes by modal group, the M codes' roles,
/// the letters some code used, the unit of lengths).
class BlockExecution {
 public:
  BlockExecution(Interpreter& interpreter, const Block& block, ModalState& state)
      : in_(interpreter), b_(block), s_(state) {}

  // The steps, in Interpreter::run's order (interpreter_modal.cpp unless noted).
  void refuse_words_after_end() const;
  void group_g_codes();
  void classify_m_codes();
  void set_units();
  void set_feed();
  void set_spindle_speed();
  void select_tool();
  void change_tool();
  void switch_spindle();
  void switch_coolant();
  void switch_outputs();  ///< heads' deposition codes, M62..M65, M67/M68
  void dwell();
  void set_plane();
  void set_length_offset();
  void set_work_offset();
  void set_distance_modes();
  void move();  ///< interpreter_motion.cpp
  void refuse_unused_words() const;
  void stop_or_end();

 private:
  /// A G code's place in its modal group; code -1: the group has none on this line.
  struct Slot {
    int code = -1;
    int column = 0;
  };
  enum GGroup {
    kMotion,
    kPlane,
    kDistance,
    kArcDistance,
    kFeedMode,
    kUnits,
    kCutter,
    kLength,
    kCoords,
    kPath,
    kDwell,
    kMachineCoords,
    kGGroups
  };
  /// What one M code on the line does: a head's code, a role, or generic I/O.
  struct MAction {
    Interpreter::MRole role = Interpreter::MRole::None;
    int head_code = -1;  ///< index into the interpreter's head_codes_
    int io = 0;          ///< 62..68 for generic I/O
    int column = 0;
    int m = 0;
  };
  using Role = Interpreter::MRole;

  [[noreturn]] void fail(int column, const std::string& message) const { in_.fail(b_, column, message); }
  Event& event(EventKind kind, int column);
  int find_head_code(int m, int tool_after_change) const;
  void switch_head(const MAction& a);
  void set_digital_output(const MAction& a);
  void set_analog_output(const MAction& a);

  // motion (interpreter_motion.cpp)
  void set_motion_mode();
  bool arc_mode() const;  ///< G2 or G3 in effect
  void check_machine_coordinates() const;
  Motion straight_or_arc(int first_axis_column);
  void target(Motion& m) const;
  int motion_column(int first_axis_column) const;
  void arc_centre(Motion& m, int column);
  std::array<double, 2> centre_from_radius(const Motion& m, int column);
  std::array<double, 2> centre_from_offsets(const Motion& m, int column);

  Interpreter& in_;
  const Block& b_;
  ModalState& s_;
  std::array<Slot, kGGroups> g_{};
  std::array<MAction, Block::kMaxCodes> actions_{};
  int action_count_ = 0;
  std::uint32_t used_ = 0;          ///< letters some code used
  std::uint32_t dwell_letters_ = 0;  ///< the G4's P (or Fanuc X): not an axis word
  double unit_ = 1.0;               ///< mm per length unit of the line (G20/G21)
};

}  // namespace hybridctl::gcode
