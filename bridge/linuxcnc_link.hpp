#pragma once
// The bridge's link to a running LinuxCNC: a child process running the agent
// (bridge/linuxcnc_agent.py, embedded in the binary) under /usr/bin/python3, which uses
// LinuxCNC's own Python API (`linuxcnc.stat`, `command`, `error_channel`). One request,
// one reply, in JSON lines over the child's stdin and stdout; every call blocks until the
// reply (a status takes about a millisecond, starting a program about 50 ms).
//
//   bridge::LinuxcncLink link;                  // starts the agent
//   link.prepare(5.0);                          // e-stop reset, on, homed, AUTO, 500 % feed
//   link.run("/tmp/segment-1.ngc");
//   bridge::LinuxcncStatus s = link.status();   // s.connected false while LinuxCNC is down

#include <array>
#include <chrono>
#include <stdexcept>
#include <cstdint>
#include <string>
#include <sys/types.h>
#include <vector>

namespace hybridctl::bridge {

/// A message from LinuxCNC's error channel (operator errors, G-code errors, texts).
struct LinuxcncMessage {
  bool error = false;  ///< NML_ERROR or OPERATOR_ERROR (else a text or display message)
  std::string text;
};

/// LinuxCNC's status as the agent read it (`linuxcnc.stat`), in LinuxCNC's own terms.
struct LinuxcncStatus {
  bool connected = false;  ///< false: LinuxCNC is not running (or not answering); `why` says what
  std::string why;
  std::string ini;         ///< the INI file LinuxCNC runs
  bool estop = false;
  bool enabled = false;    ///< machine on
  bool homed = false;      ///< every joint
  int task_state = 0;      ///< STATE_ESTOP 1, ESTOP_RESET 2, OFF 3, ON 4
  int task_mode = 0;       ///< MANUAL 1, AUTO 2, MDI 3
  int interp_state = 0;    ///< IDLE 1, READING 2, PAUSED 3, WAITING 4
  int exec_state = 0;
  bool paused = false;
  std::string file;        ///< the open program file
  int motion_line = 0;     ///< the file line of the motion executing now
  int current_line = 0;    ///< the file line the interpreter is at (ahead of motion)
  int queue = 0;           ///< motions queued in the trajectory planner
  bool inpos = false;
  std::array<double, 3> position{};  ///< actual position, machine frame, mm
  int tool = 0;            ///< tool in the spindle
  double spindle_speed = 0;
  int spindle_direction = 0;          ///< 1 forward, -1 reverse, 0 off
  std::array<bool, 4> dout{};         ///< motion.digital-out-00..03 (M62-M65)
  double feedrate = 1;                ///< feed override, 1 = 100 %
  std::vector<LinuxcncMessage> messages;  ///< error channel, since the last status

  static constexpr int kEstop = 1, kOn = 4;
  static constexpr int kInterpIdle = 1, kInterpPaused = 3;
};

/// The agent cannot be started, died, did not answer in time, or answered an action
/// with an error (LinuxCNC refused it; the message is LinuxCNC's or the agent's).
class LinkError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Parses one status reply of the agent (its JSON line). Throws LinkError naming what is
/// missing or malformed.
LinuxcncStatus parse_status(const std::string& reply);

class LinuxcncLink {
 public:
  struct Options {
    std::string python = "/usr/bin/python3";  ///< the Python that has Debian's `linuxcnc` module
    std::chrono::milliseconds reply_timeout{15000};
  };
  LinuxcncLink() : LinuxcncLink(Options{}) {}
  explicit LinuxcncLink(Options options);
  ~LinuxcncLink();
  LinuxcncLink(const LinuxcncLink&) = delete;
  LinuxcncLink& operator=(const LinuxcncLink&) = delete;

  LinuxcncStatus status();
  /// Out of e-stop, machine on, homed (homing when needed), AUTO mode, feed override
  /// `feed_override` (1 = 100 %; 0 leaves it).
  void prepare(double feed_override);
  /// Opens `file` and starts it (AUTO_RUN from its first line); returns once running.
  void run(const std::string& file);
  void pause();
  void resume();
  /// Stops the program, then spindle off and the digital outputs off (MDI).
  void abort();

 private:
  std::string request(const std::string& json_line);
  void act(const std::string& json_line);

  Options options_;
  pid_t child_ = -1;
  int to_child_ = -1;
  int from_child_ = -1;
  std::string buffered_;
  std::uint64_t last_id_ = 0;  // the number of the last request sent
};

}  // namespace hybridctl::bridge
