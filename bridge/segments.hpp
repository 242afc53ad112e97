#pragma once
// How the bridge feeds a streamed program to LinuxCNC: as segment files, each a run of
// whole program lines that LinuxCNC opens and runs in AUTO mode from its first line
// (docs/bridge.md says why: its own interpreter and trajectory planner with blending
// inside a segment, about 0.1 s of standstill between two).
//
// A segment ends only at a safe point: after a line where every motion-synchronised
// digital output (M62/M64 on, M63/M65 off; the DED head's laser and powder) is off and
// before a rapid (G0), a tool change (M6) or a `%` line, or at the program's last line.
// So the machine never stands still with the laser on or a cutter in a cut.
//
// A segment file is `%`, the lines as streamed (a `%` line of the program written as the
// comment `(%)`, so only the wrapper ends the file), `%`: file line f is program line
// first_line + f - 2. LinuxCNC keeps its modal state (units, offsets, feed, tool, spindle)
// from one segment to the next because a `%` end is not a program end (M2/M30).
//
//   SegmentFeeder feeder;
//   feeder.add_lines(chunk.first_line, chunk.payload);
//   if (auto s = feeder.next_segment(program_line_count)) write(segment_file_text(*s));

#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace hybridctl::bridge {

struct Segment {
  std::uint32_t first_line = 0;  ///< program line of the segment's first line
  std::vector<std::string> lines;
  std::uint32_t outputs_at_start = 0;  ///< digital outputs on before its first line (bit n: P n)

  std::uint32_t last_line() const { return first_line + std::uint32_t(lines.size()) - 1; }
};

/// The segment file's text (see above).
std::string segment_file_text(const Segment& segment);

/// The program line of LinuxCNC's file line `file_line` in `segment`'s file; 0 before the
/// first program line (the `%` wrapper, or LinuxCNC's 0 for "none yet").
std::uint32_t program_line(const Segment& segment, int file_line);

/// The digital outputs on after `text` given those on before it (M62/M64 P n on,
/// M63/M65 P n off; a line that does not parse changes nothing).
std::uint32_t outputs_after(std::string_view text, std::uint32_t outputs_before);

/// 0 for a line with M0 (program stop), 1 for M1 (optional stop), else -1.
int stop_code(std::string_view text);

/// A line with an X, Y or Z word (a move, or an offset that moves nothing: either way
/// not a line LinuxCNC can have passed silently).
bool moves(std::string_view text);

/// A line with M2 or M30 (program end).
bool program_end(std::string_view text);

/// A line a segment may start with: a rapid (G0), a tool change (M6) or a `%` line.
bool safe_start(std::string_view text);

class SegmentFeeder {
 public:
  /// Lines first_line.. from a chunk payload (lines each ending in '\n').
  void add_lines(std::uint32_t first_line, std::string_view payload);

  /// The pending lines up to the last safe point, removed from the pending lines;
  /// nullopt when there is none yet. `program_lines`: the program's line count (its last
  /// line is always a safe point).
  std::optional<Segment> next_segment(std::uint32_t program_lines);

  /// Puts the lines from `from_line` on of a segment LinuxCNC did not finish (e-stop, an
  /// error) back in front of the pending lines.
  void requeue(const Segment& segment, std::uint32_t from_line);

  void clear();
  bool empty() const { return pending_.empty(); }
  std::uint32_t next_line() const { return pending_.empty() ? 0 : pending_.front().number; }

 private:
  struct Line {
    std::uint32_t number;
    std::string text;
  };
  std::deque<Line> pending_;
  std::uint32_t outputs_ = 0;  // digital outputs on before the first pending line
};

}  // namespace hybridctl::bridge
