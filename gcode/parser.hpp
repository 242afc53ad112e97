#pragma once
// The G-code parser: one line of text into one Block of words.
//
// What it reads (RS274NGC as LinuxCNC reads it, and the Fanuc-style ISO subset hybridctl
// writes): words (a letter and a number, letters in either case, numbers such as `10`,
// `-.5`, `1.`, `+2`, spaces allowed between letter and number), comments in `( )` and
// after `;`, an `N` line number first on the line, `%` lines, and Fanuc program-number
// lines `O1000`. It does not read expressions, parameters (`#1`), subroutines (`O100
// sub`) or block delete (`/`): those are errors, as is anything else it cannot read.
//
// Errors are InputError (GcodeError) with the text `FILE:line:column: ` + what was found
// + what was expected. Parsing allocates nothing per line: a Block is reused.

#include <array>
#include <cstdint>
#include <string>
#include <string_view>

#include "common/error.hpp"

namespace hybridctl::gcode {

/// A G-code error at a place. what() is "FILE:line:column: message".
class GcodeError : public InputError {
 public:
  GcodeError(const std::string& file, int line, int column, const std::string& message);
  int line() const { return line_; }
  int column() const { return column_; }
  /// The message without the place.
  const std::string& message() const { return message_; }

 private:
  int line_;
  int column_;
  std::string message_;
};

/// A G or M code and where it stands. G codes are kept in tenths (G90.1 = 901, G1 = 10),
/// M codes as written (M64 = 64).
struct Code {
  int value = 0;
  int column = 0;
};

/// One line of G-code as words. Letters other than G and M appear at most once a line.
struct Block {
  static constexpr int kMaxCodes = 8;  ///< G codes, and M codes, per line

  int line = 0;             ///< 1-based line number in the file
  bool percent = false;     ///< a `%` line (start or end of a program's text)
  int n = -1;               ///< the N line number, -1 when absent
  int program_number = -1;  ///< Fanuc `O1000` line: the number, -1 when absent

  std::array<Code, kMaxCodes> g{};  ///< G codes in line order, in tenths
  int g_count = 0;
  std::array<Code, kMaxCodes> m{};  ///< M codes in line order
  int m_count = 0;

  std::uint32_t letters = 0;        ///< bit (letter - 'A') set when that letter's word is present
  std::array<double, 26> values{};  ///< by letter - 'A', valid where the bit is set
  std::array<int, 26> columns{};    ///< 1-based column of each word's letter

  /// The text of the last comment on the line, without `( )` or `;`, trimmed; empty when
  /// none. A view into the line text: valid while that text lives.
  std::string_view comment;
  int comment_column = 0;

  bool has(char letter) const { return (letters >> (letter - 'A')) & 1u; }
  double value(char letter) const { return values[letter - 'A']; }
  int column(char letter) const { return columns[letter - 'A']; }
  /// No words at all (blank, comment-only or `%` line).
  bool no_words() const { return letters == 0 && g_count == 0 && m_count == 0 && program_number < 0; }

  void clear() {
    percent = false;
    n = -1;
    program_number = -1;
    g_count = 0;
    m_count = 0;
    letters = 0;
    comment = {};
    comment_column = 0;
  }
};

/// Parses lines of one file; the file name appears in error messages.
class Parser {
 public:
  explicit Parser(std::string file_name = "<gcode>") : file_(std::move(file_name)) {}

  /// Parses `text` (one line, without its line break; a trailing '\r' is ignored) into
  /// `block`, which is cleared first. Throws GcodeError naming line_number and the column.
  void parse_line(std::string_view text, int line_number, Block& block) const;

  const std::string& file_name() const { return file_; }

 private:
  std::string file_;
};

/// Calls f(line_text, line_number) for each line of `text` (split at '\n'; a '\r' before
/// it is dropped), numbering from 1. A final line without '\n' counts; an empty text has
/// no lines.
template <class F>
void for_each_line(std::string_view text, F&& f) {
  int number = 0;
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string_view::npos) end = text.size();
    std::size_t stop = end;
    if (stop > start && text[stop - 1] == '\r') --stop;
    f(text.substr(start, stop - start), ++number);
    start = end + 1;
  }
}

/// "G1", "G90.1", "M64": a code as written, for messages.
std::string g_code_name(int tenths);
std::string m_code_name(int value);

}  // namespace hybridctl::gcode
