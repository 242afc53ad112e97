#include "gcode/parser.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>

namespace hybridctl::gcode {

GcodeError::GcodeError(const std::string& file, int line, int column, const std::string& message)
    : InputError(file + ":" + std::to_string(line) + ":" + std::to_string(column) + ": " + message),
      line_(line),
      column_(column),
      message_(message) {}

std::string g_code_name(int tenths) {
  std::string name = "G" + std::to_string(tenths / 10);
  if (tenths % 10 != 0) name += "." + std::to_string(tenths % 10);
  return name;
}

std::string m_code_name(int value) { return "M" + std::to_string(value); }

namespace {

/// Exact powers of ten: a mantissa below 2^53 divided by one of these is correctly rounded.
constexpr double kPow10[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
                             1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
constexpr int kMaxFastDigits = 15;  ///< significant digits that fit a double's mantissa exactly

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }
bool is_digit(char c) { return c >= '0' && c <= '9'; }

/// How a character is shown in a message.
std::string shown(char c) {
  if (c >= 0x21 && c < 0x7f) return std::string("'") + c + "'";
  if (c == ' ') return "a space";
  char buf[16];
  std::snprintf(buf, sizeof buf, "byte 0x%02X", static_cast<unsigned char>(c));
  return buf;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
  return s;
}

/// One line being read into a block: the read position, the column of a position, and
/// one function per thing a line holds (comments, '%', words).
class LineReader {
 public:
  LineReader(const std::string& file, int line, std::string_view text, Block& block)
      : file_(file), line_(line), begin_(text.data()), end_(text.data() + text.size()), p_(begin_), block_(block) {}

  bool done() const { return p_ >= end_; }
  char peek() const { return *p_; }
  void skip() { ++p_; }
  void read_comment();
  void read_comment_to_end();
  void read_percent();
  void read_word();

 private:
  /// A word's number as written: its value and its text (sign included).
  struct Number {
    double value = 0;
    std::string_view text;
  };

  int column(const char* at) const { return static_cast<int>(at - begin_) + 1; }
  [[noreturn]] void fail(int column, const std::string& message) const {
    throw GcodeError(file_, line_, column, message);
  }
  char read_letter();
  Number read_number(char letter);
  double exact_value(const char* number_at, char letter) const;
  void store_g(const Number& n, int col);
  void store_m(const Number& n, int col);
  void store_line_number(const Number& n, int col);
  void store_program_number(const Number& n, int col);
  void store_other(char letter, const Number& n, int col);

  const std::string& file_;
  const int line_;
  const char* const begin_;
  const char* const end_;
  const char* p_;
  Block& block_;
  bool any_word_ = false;
};

// A comment in ( ): they do not nest and end on their line.
void LineReader::read_comment() {
  const char* q = p_ + 1;
  while (q < end_ && *q != ')') {
    if (*q == '(')
      fail(column(q), "found '(' inside the comment opened at column " + std::to_string(column(p_)) +
                          "; expected ')' first (comments do not nest)");
    ++q;
  }
  if (q == end_) fail(column(p_), "found a comment '(' with no ')' before the end of the line; expected ')'");
  block_.comment = trim(std::string_view(p_ + 1, static_cast<std::size_t>(q - p_ - 1)));
  block_.comment_column = column(p_);
  p_ = q + 1;
}

// A comment after ';': the rest of the line.
void LineReader::read_comment_to_end() {
  block_.comment = trim(std::string_view(p_ + 1, static_cast<std::size_t>(end_ - p_ - 1)));
  block_.comment_column = column(p_);
  p_ = end_;
}

void LineReader::read_percent() {
  if (any_word_) fail(column(p_), "found '%' after words; expected '%' alone on its line");
  block_.percent = true;
  ++p_;
}

// A word: letter, optional spaces, number; then stored by its letter.
void LineReader::read_word() {
  const char* word_at = p_;
  const char letter = read_letter();
  const Number n = read_number(letter);
  const int col = column(word_at);
  switch (letter) {
    case 'G': store_g(n, col); break;
    case 'M': store_m(n, col); break;
    case 'N': store_line_number(n, col); break;
    case 'O': store_program_number(n, col); break;
    default: store_other(letter, n, col); break;
  }
  if (block_.program_number >= 0 && letter != 'O')
    fail(col, "found " + std::string(1, letter) +
                  " after an O program number; expected the O number alone on its "
                  "line (O words for subroutines are not supported)");
  any_word_ = true;
}

char LineReader::read_letter() {
  const char c = *p_;
  char letter = c;
  if (letter >= 'a' && letter <= 'z') letter = static_cast<char>(letter - 'a' + 'A');
  if (letter < 'A' || letter > 'Z') {
    if (c == '#' || c == '[')
      fail(column(p_), "found " + shown(c) + ": parameters and expressions are not supported; expected a word such as X10");
    if (c == '/') fail(column(p_), "found '/': block delete is not supported; expected a word such as G1");
    fail(column(p_), "found " + shown(c) +
                         "; expected a word (a letter and a number such as X-1.5), a comment in ( ) or "
                         "after ;, or the end of the line");
  }
  if (block_.percent) fail(column(p_), "found a word on a '%' line; expected '%' alone on its line");
  ++p_;
  while (p_ < end_ && is_space(*p_)) ++p_;
  return letter;
}

// The number: [+-] digits [. digits], at least one digit. Up to kMaxFastDigits
// significant digits it is exact as mantissa / 10^fraction; beyond, from_chars.
LineReader::Number LineReader::read_number(char letter) {
  const char* number_at = p_;
  bool negative = false;
  if (p_ < end_ && (*p_ == '+' || *p_ == '-')) {
    negative = *p_ == '-';
    ++p_;
  }
  std::uint64_t mantissa = 0;
  int digits = 0;      // significant digits taken into the mantissa
  int fraction = 0;    // of which after the point
  int all_digits = 0;  // every digit seen
  bool lost = false;   // more significant digits than the fast path holds
  while (p_ < end_ && is_digit(*p_)) {
    if (mantissa != 0 || *p_ != '0') {
      if (digits < kMaxFastDigits) {
        mantissa = mantissa * 10 + static_cast<std::uint64_t>(*p_ - '0');
        ++digits;
      } else {
        lost = true;
      }
    }
    ++all_digits;
    ++p_;
  }
  if (p_ < end_ && *p_ == '.') {
    ++p_;
    while (p_ < end_ && is_digit(*p_)) {
      if (digits < kMaxFastDigits && !lost) {
        mantissa = mantissa * 10 + static_cast<std::uint64_t>(*p_ - '0');
        if (mantissa != 0) ++digits;
        ++fraction;
      } else if (*p_ != '0') {
        lost = true;
      }
      ++all_digits;
      ++p_;
    }
  }
  if (all_digits == 0) {
    const std::string found = number_at < end_ ? shown(*number_at) : std::string("the end of the line");
    fail(column(number_at), "found " + found + " after " + std::string(1, letter) + "; expected a number such as " +
                                std::string(1, letter) + (letter == 'G' || letter == 'M' ? "1" : "10.5"));
  }
  double value = !lost && fraction <= 22 ? static_cast<double>(mantissa) / kPow10[fraction]
                                         : exact_value(number_at, letter);
  if (negative) value = -value;
  return {value, std::string_view(number_at, static_cast<std::size_t>(p_ - number_at))};
}

// Rare: more digits than a double holds exactly. from_chars rounds correctly.
double LineReader::exact_value(const char* number_at, char letter) const {
  const char* first = number_at + (number_at < end_ && (*number_at == '+' || *number_at == '-') ? 1 : 0);
  double value = 0;
  const auto [stop, error] = std::from_chars(first, p_, value);
  if (error != std::errc() || stop != p_ || !std::isfinite(value))
    fail(column(number_at), "found " + std::string(1, letter) + std::string(number_at, p_) +
                                ", a number out of range; expected a number a double can hold");
  return value;
}

void LineReader::store_g(const Number& n, int col) {
  const double tenths = n.value * 10.0;
  const double rounded = std::nearbyint(tenths);
  if (n.value < 0 || std::abs(tenths - rounded) > 1e-6 || rounded > 99999)
    fail(col, "found G" + std::string(n.text) + "; expected a G code such as G1 or G90.1 (one decimal)");
  if (block_.g_count == Block::kMaxCodes)
    fail(col, "found more than " + std::to_string(Block::kMaxCodes) + " G codes; expected fewer");
  block_.g[block_.g_count++] = Code{static_cast<int>(rounded), col};
}

void LineReader::store_m(const Number& n, int col) {
  if (n.value < 0 || n.value != std::nearbyint(n.value) || n.value > 99999)
    fail(col, "found M" + std::string(n.text) + "; expected an M code such as M3 (a whole number)");
  if (block_.m_count == Block::kMaxCodes)
    fail(col, "found more than " + std::to_string(Block::kMaxCodes) + " M codes; expected fewer");
  block_.m[block_.m_count++] = Code{static_cast<int>(n.value), col};
}

void LineReader::store_line_number(const Number& n, int col) {
  if (any_word_) fail(col, "found an N line number after other words; expected it first on the line");
  if (n.value < 0 || n.value != std::nearbyint(n.value) || n.value > 99999999)
    fail(col, "found N" + std::string(n.text) + "; expected a line number such as N10");
  block_.n = static_cast<int>(n.value);
}

void LineReader::store_program_number(const Number& n, int col) {
  if (any_word_ && block_.n < 0)
    fail(col, "found an O program number after other words; expected it alone on its line");
  if (n.value < 0 || n.value != std::nearbyint(n.value) || n.value > 99999)
    fail(col, "found O" + std::string(n.text) + "; expected a program number such as O1000");
  block_.program_number = static_cast<int>(n.value);
}

void LineReader::store_other(char letter, const Number& n, int col) {
  const int bit = letter - 'A';
  if ((block_.letters >> bit) & 1u)
    fail(col, "found a second " + std::string(1, letter) + " word (the first is at column " +
                  std::to_string(block_.columns[bit]) + "); expected each letter at most once a line");
  block_.letters |= 1u << bit;
  block_.values[bit] = n.value;
  block_.columns[bit] = col;
}

}  // namespace

void Parser::parse_line(std::string_view text, int line_number, Block& block) const {
  block.clear();
  block.line = line_number;
  LineReader line(file_, line_number, text, block);
  while (!line.done()) {
    const char c = line.peek();
    if (is_space(c))
      line.skip();
    else if (c == '(')
      line.read_comment();
    else if (c == ';')
      line.read_comment_to_end();
    else if (c == '%')
      line.read_percent();
    else
      line.read_word();
  }
}

}  // namespace hybridctl::gcode
