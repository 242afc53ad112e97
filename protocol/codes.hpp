#pragma once
// The program-stream protocol's vocabulary: controller states, commands, alarm codes and
// result codes, each as ONE table in code. docs/protocol.md embeds the tables rendered by
// alarm_table_markdown() and result_table_markdown(); a test keeps the two identical.
// Also the error value every decoder returns instead of throwing (ProtocolError,
// Expected<T>), because decoders read bytes from the network.

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <variant>

namespace hybridctl::protocol {

/// Protocol version carried in the status block (register 0).
inline constexpr std::uint16_t kProtocolVersion = 1;

/// What the controller is doing. Numbers are wire values.
enum class ControllerState : std::uint16_t {
  Idle = 0,          ///< no program running (a program may be set and chunks may be queued)
  Running = 1,       ///< executing the program
  FeedHold = 2,      ///< motion held by FEED_HOLD or after RESET_ALARM of an interrupted program
  ProgramStop = 3,   ///< stopped at M0, waits for OPERATOR_ACK
  OptionalStop = 4,  ///< stopped at M1 (optional stop switch on), waits for OPERATOR_ACK
  Alarm = 5,         ///< stopped by an alarm (status `alarm` says which), waits for RESET_ALARM
  Completed = 6,     ///< every line of the program executed
  Aborted = 7,       ///< the program was ended by ABORT
};
inline constexpr std::uint16_t kControllerStateCount = 8;

/// Host -> controller commands. Numbers are wire values; 0 is "no command".
enum class CommandCode : std::uint16_t {
  None = 0,
  SetProgram = 1,   ///< args: identity (64 bits) and program line count (32 bits)
  Start = 2,
  FeedHold = 3,
  Resume = 4,
  Abort = 5,
  ResetAlarm = 6,
  OperatorAck = 7,  ///< continue after M0 / M1
};
inline constexpr std::uint16_t kCommandCodeCount = 8;

/// Why the controller stopped. Numbers are wire values; 0 is "no alarm".
enum class AlarmCode : std::uint16_t {
  None = 0,
  EnvelopeViolation = 1,
  RapidIntoMaterial = 2,
  ToolNotInMagazine = 3,
  DepositionWithoutHead = 4,
  HostHeartbeatLost = 5,
  GcodeError = 6,
  ProgramIdentityMismatch = 7,
  EmergencyStop = 8,
  SpindleDepositionConflict = 9,
  ControllerRestarted = 10,
  DepositionStarved = 11,
  DepositionOverAir = 12,
  NozzleCollision = 13,
  LinuxcncError = 14,      // the LinuxCNC bridge (docs/bridge.md)
  LinuxcncLost = 15,       // the LinuxCNC bridge (docs/bridge.md)
};
inline constexpr std::uint16_t kAlarmCodeCount = 16;

/// Outcome of a chunk write or a command, reported in the status block; also the kind
/// of every decoding error. Numbers are wire values.
enum class ResultCode : std::uint16_t {
  None = 0,
  Accepted = 1,
  Duplicate = 2,
  Gap = 3,
  BadCrc = 4,
  BadLength = 5,
  TooLong = 6,
  BadLines = 7,
  BadText = 8,
  LineMismatch = 9,
  BufferFull = 10,
  NoProgram = 11,
  IdentityMismatch = 12,
  NotAccepting = 13,
  UnknownCommand = 14,
  WrongState = 15,
  BadArgument = 16,
  ConditionActive = 17,
  BadValue = 18,
};
inline constexpr std::uint16_t kResultCodeCount = 19;

/// One row of the alarm table.
struct AlarmInfo {
  AlarmCode code;
  std::string_view name;      ///< UPPER_SNAKE name shown by the CLI
  std::string_view meaning;   ///< what happened
  std::string_view action;    ///< what the operator should do
  bool has_line;              ///< status `alarm_line` names the G-code line at fault
  /// A warning: the controller reports it (status `alarm`, `alarm_line`) and goes on in
  /// its state; every other alarm stops the machine in ALARM.
  bool warning = false;
};

/// One row of the result-code table.
struct ResultInfo {
  ResultCode code;
  std::string_view name;
  std::string_view meaning;
  std::string_view action;    ///< what the host (or its operator) should do
};

/// The tables, indexed by wire value.
const AlarmInfo& alarm_info(AlarmCode code);
const ResultInfo& result_info(ResultCode code);

std::string_view to_string(ControllerState state);  ///< "IDLE", "RUNNING", ...
std::string_view to_string(CommandCode code);       ///< "SET_PROGRAM", ...
std::string_view to_string(AlarmCode code);         ///< alarm_info(code).name
std::string_view to_string(ResultCode code);        ///< result_info(code).name

/// Wire value -> enum; nullopt for values this protocol version does not define.
std::optional<ControllerState> controller_state_from_wire(std::uint16_t value);
std::optional<CommandCode> command_code_from_wire(std::uint16_t value);
std::optional<AlarmCode> alarm_code_from_wire(std::uint16_t value);
std::optional<ResultCode> result_code_from_wire(std::uint16_t value);

/// The tables as Markdown (header row, separator, one row per code, trailing newline),
/// exactly as docs/protocol.md holds them between <!-- alarm-table --> and
/// <!-- /alarm-table --> (resp. result-table).
std::string alarm_table_markdown();
std::string result_table_markdown();

/// What a decoder found wrong: the result code a controller reports for it, and a message
/// naming the field (register, byte, frame) and what was expected.
struct ProtocolError {
  ResultCode code = ResultCode::BadValue;
  std::string message;
};

/// A value or the ProtocolError that prevented it (std::expected is C++23).
/// value() on an error is a programming error and throws std::logic_error.
template <class T>
class Expected {
 public:
  Expected(T value) : data_(std::move(value)) {}                 // NOLINT: implicit by design
  Expected(ProtocolError error) : data_(std::move(error)) {}     // NOLINT
  Expected(ResultCode code, std::string message) : data_(ProtocolError{code, std::move(message)}) {}

  bool ok() const { return data_.index() == 0; }
  explicit operator bool() const { return ok(); }

  const T& value() const& {
    check();
    return std::get<0>(data_);
  }
  T& value() & {
    check();
    return std::get<0>(data_);
  }
  T&& value() && {
    check();
    return std::get<0>(std::move(data_));
  }
  const T& operator*() const& { return value(); }
  T& operator*() & { return value(); }
  const T* operator->() const { return &value(); }
  T* operator->() { return &value(); }

  /// The error; on a value, a ProtocolError with code None and an empty message.
  const ProtocolError& error() const {
    static const ProtocolError no_error{ResultCode::None, {}};
    return ok() ? no_error : std::get<1>(data_);
  }

 private:
  void check() const {
    if (!ok()) throw std::logic_error("Expected::value() on an error: " + std::get<1>(data_).message);
  }
  std::variant<T, ProtocolError> data_;
};

}  // namespace hybridctl::protocol
