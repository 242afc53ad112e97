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

}  // namespace

void Parser::fail(int line, int column, const std::string& message) const {
  throw GcodeError(file_, line, column, message);
}

void Parser::parse_line(std::string_view text, int line_number, Block& block) const {
  block.clear();
  block.line = line_number;
  const char* const begin = text.data();
  const char* const end = begin + text.size();
  const char* p = begin;
  const auto column = [begin](const char* at) { return static_cast<int>(at - begin) + 1; };
  bool any_word = false;

  while (p < end) {
    const char c = *p;
    if (is_space(c)) {
      ++p;
      continue;
    }
    if (c == '(') {
      const char* q = p + 1;
      while (q < end && *q != ')') {
        if (*q == '(')
          fail(line_number, column(q),
               "found '(' inside the comment opened at column " + std::to_string(column(p)) +
                   "; expected ')' first (comments do not nest)");
        ++q;
      }
      if (q == end)
        fail(line_number, column(p), "found a comment '(' with no ')' before the end of the line; expected ')'");
      block.comment = trim(std::string_view(p + 1, static_cast<std::size_t>(q - p - 1)));
      block.comment_column = column(p);
      p = q + 1;
      continue;
    }
    if (c == ';') {
      block.comment = trim(std::string_view(p + 1, static_cast<std::size_t>(end - p - 1)));
      block.comment_column = column(p);
      break;
    }
    if (c == '%') {
      if (any_word) fail(line_number, column(p), "found '%' after words; expected '%' alone on its line");
      block.percent = true;
      ++p;
      continue;
    }

    // A word: letter, optional spaces, number.
    char letter = c;
    if (letter >= 'a' && letter <= 'z') letter = static_cast<char>(letter - 'a' + 'A');
    if (letter < 'A' || letter > 'Z') {
      if (c == '#' || c == '[')
        fail(line_number, column(p),
             "found " + shown(c) + ": parameters and expressions are not supported; expected a word such as X10");
      if (c == '/')
        fail(line_number, column(p), "found '/': block delete is not supported; expected a word such as G1");
      fail(line_number, column(p),
           "found " + shown(c) +
               "; expected a word (a letter and a number such as X-1.5), a comment in ( ) or "
               "after ;, or the end of the line");
    }
    if (block.percent) fail(line_number, column(p), "found a word on a '%' line; expected '%' alone on its line");
    const char* word_at = p;
    ++p;
    while (p < end && is_space(*p)) ++p;

    // The number: [+-] digits [. digits], at least one digit.
    const char* number_at = p;
    bool negative = false;
    if (p < end && (*p == '+' || *p == '-')) {
      negative = *p == '-';
      ++p;
    }
    std::uint64_t mantissa = 0;
    int digits = 0;      // significant digits taken into the mantissa
    int fraction = 0;    // of which after the point
    int all_digits = 0;  // every digit seen
    bool lost = false;   // more significant digits than the fast path holds
    while (p < end && is_digit(*p)) {
      if (mantissa != 0 || *p != '0') {
        if (digits < kMaxFastDigits) {
          mantissa = mantissa * 10 + static_cast<std::uint64_t>(*p - '0');
          ++digits;
        } else {
          lost = true;
        }
      }
      ++all_digits;
      ++p;
    }
    if (p < end && *p == '.') {
      ++p;
      while (p < end && is_digit(*p)) {
        if (digits < kMaxFastDigits && !lost) {
          mantissa = mantissa * 10 + static_cast<std::uint64_t>(*p - '0');
          if (mantissa != 0) ++digits;
          ++fraction;
        } else if (*p != '0') {
          lost = true;
        }
        ++all_digits;
        ++p;
      }
    }
    if (all_digits == 0) {
      const std::string found = number_at < end ? shown(*number_at) : std::string("the end of the line");
      fail(line_number, column(number_at),
           "found " + found + " after " + std::string(1, letter) + "; expected a number such as " +
               std::string(1, letter) + (letter == 'G' || letter == 'M' ? "1" : "10.5"));
    }
    double value;
    if (!lost && fraction <= 22) {
      value = static_cast<double>(mantissa) / kPow10[fraction];
    } else {
      // Rare: more digits than a double holds exactly. from_chars rounds correctly.
      const char* first = number_at + (number_at < end && (*number_at == '+' || *number_at == '-') ? 1 : 0);
      value = 0;
      const auto [stop, error] = std::from_chars(first, p, value);
      if (error != std::errc() || stop != p || !std::isfinite(value))
        fail(line_number, column(number_at),
             "found " + std::string(1, letter) + std::string(number_at, p) +
                 ", a number out of range; expected a number a double can hold");
    }
    if (negative) value = -value;
    const int col = column(word_at);

    switch (letter) {
      case 'G': {
        const double tenths = value * 10.0;
        const double rounded = std::nearbyint(tenths);
        if (value < 0 || std::abs(tenths - rounded) > 1e-6 || rounded > 99999)
          fail(line_number, col,
               "found G" + std::string(number_at, p) + "; expected a G code such as G1 or G90.1 (one decimal)");
        if (block.g_count == Block::kMaxCodes)
          fail(line_number, col, "found more than " + std::to_string(Block::kMaxCodes) + " G codes; expected fewer");
        block.g[block.g_count++] = Code{static_cast<int>(rounded), col};
        break;
      }
      case 'M': {
        if (value < 0 || value != std::nearbyint(value) || value > 99999)
          fail(line_number, col,
               "found M" + std::string(number_at, p) + "; expected an M code such as M3 (a whole number)");
        if (block.m_count == Block::kMaxCodes)
          fail(line_number, col, "found more than " + std::to_string(Block::kMaxCodes) + " M codes; expected fewer");
        block.m[block.m_count++] = Code{static_cast<int>(value), col};
        break;
      }
      case 'N': {
        if (any_word) fail(line_number, col, "found an N line number after other words; expected it first on the line");
        if (value < 0 || value != std::nearbyint(value) || value > 99999999)
          fail(line_number, col, "found N" + std::string(number_at, p) + "; expected a line number such as N10");
        block.n = static_cast<int>(value);
        break;
      }
      case 'O': {
        if (any_word && block.n < 0)
          fail(line_number, col, "found an O program number after other words; expected it alone on its line");
        if (value < 0 || value != std::nearbyint(value) || value > 99999)
          fail(line_number, col, "found O" + std::string(number_at, p) + "; expected a program number such as O1000");
        block.program_number = static_cast<int>(value);
        break;
      }
      default: {
        const int bit = letter - 'A';
        if ((block.letters >> bit) & 1u)
          fail(line_number, col,
               "found a second " + std::string(1, letter) + " word (the first is at column " +
                   std::to_string(block.columns[bit]) + "); expected each letter at most once a line");
        block.letters |= 1u << bit;
        block.values[bit] = value;
        block.columns[bit] = col;
        break;
      }
    }
    if (block.program_number >= 0 && letter != 'O')
      fail(line_number, col,
           "found " + std::string(1, letter) +
               " after an O program number; expected the O number alone on its "
               "line (O words for subroutines are not supported)");
    any_word = true;
  }
}

}  // namespace hybridctl::gcode
