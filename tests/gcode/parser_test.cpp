// The G-code parser reads words, numbers in every form G-code allows, comments, N line
// numbers, '%' and Fanuc O lines; anything else is an error at FILE:line:column saying
// what was found and what was expected.

#include "gcode/parser.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <random>
#include <string>
#include <vector>

namespace {

using hybridctl::gcode::Block;
using hybridctl::gcode::for_each_line;
using hybridctl::gcode::GcodeError;
using hybridctl::gcode::Parser;

Block parse(const std::string& text, int line = 1) {
  Block b;
  Parser("p.ngc").parse_line(text, line, b);
  return b;
}

/// The error text for a line that must fail.
std::string error_of(const std::string& text, int line = 7) {
  try {
    parse(text, line);
  } catch (const GcodeError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected an error for: " << text;
  return {};
}

TEST(Parser, ReadsWordsInEitherCaseWithNumbersInEveryForm) {
  const std::string line = "N10 g1 x-.5 Y1. z+2 f 100 (a comment)";
  const Block b = parse(line);
  EXPECT_EQ(b.n, 10);
  ASSERT_EQ(b.g_count, 1);
  EXPECT_EQ(b.g[0].value, 10);  // tenths
  EXPECT_EQ(b.g[0].column, 5);
  EXPECT_EQ(b.value('X'), -0.5);
  EXPECT_EQ(b.value('Y'), 1.0);
  EXPECT_EQ(b.value('Z'), 2.0);
  EXPECT_EQ(b.value('F'), 100.0);
  EXPECT_EQ(b.column('F'), 21);
  EXPECT_TRUE(b.has('X'));
  EXPECT_FALSE(b.has('I'));
  EXPECT_EQ(b.comment, "a comment");
}

TEST(Parser, KeepsGCodeDecimalsAndSeveralCodes) {
  const Block b = parse("G90.1 G17 M3 M8 S1000");
  ASSERT_EQ(b.g_count, 2);
  EXPECT_EQ(b.g[0].value, 901);
  EXPECT_EQ(b.g[1].value, 170);
  ASSERT_EQ(b.m_count, 2);
  EXPECT_EQ(b.m[0].value, 3);
  EXPECT_EQ(b.m[1].value, 8);
  EXPECT_EQ(b.value('S'), 1000.0);
}

TEST(Parser, CommentsAndBlankLinesHaveNoWords) {
  EXPECT_TRUE(parse("").no_words());
  EXPECT_TRUE(parse("   \t ").no_words());
  // The comment is a view into the line: the text must outlive the block.
  const std::string paren_line = "  ( MSG, flip the part )  ";
  const Block paren = parse(paren_line);
  EXPECT_TRUE(paren.no_words());
  EXPECT_EQ(paren.comment, "MSG, flip the part");
  const std::string semi_line = "G0 X1 ; to the side (really)";
  const Block semi = parse(semi_line);
  EXPECT_EQ(semi.comment, "to the side (really)");
  EXPECT_EQ(semi.value('X'), 1.0);
}

TEST(Parser, PercentAndProgramNumberLines) {
  EXPECT_TRUE(parse("%").percent);
  EXPECT_TRUE(parse("%").no_words());
  const std::string o_line = "O1000 (PART)";
  const Block o = parse(o_line);
  EXPECT_EQ(o.program_number, 1000);
  EXPECT_EQ(o.comment, "PART");
  EXPECT_FALSE(o.no_words());
}

TEST(Parser, NumbersAreExactlyWhatStrtodReads) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> value(-5000.0, 5000.0);
  for (int i = 0; i < 2000; ++i) {
    char text[64];
    std::snprintf(text, sizeof text, "%.*f", i % 7, value(rng));
    const Block b = parse(std::string("X") + text);
    EXPECT_EQ(b.value('X'), std::strtod(text, nullptr)) << text;
  }
  // More digits than a double holds take the slow, correctly rounded path.
  EXPECT_EQ(parse("X1.2345678901234567890123").value('X'), std::strtod("1.2345678901234567890123", nullptr));
  EXPECT_EQ(parse("X123456789012345678901").value('X'), std::strtod("123456789012345678901", nullptr));
  EXPECT_EQ(parse("X0.000000000000000000000000001").value('X'), 1e-27);
  EXPECT_EQ(parse("X-0").value('X'), 0.0);
}

TEST(Parser, ErrorsNameFileLineAndColumnWithWhatWasFoundAndExpected) {
  struct Case {
    std::string line, prefix, words;
  };
  const std::vector<Case> cases = {
      {"G1 X", "p.ngc:7:5: ", "found the end of the line after X; expected a number"},
      {"G1 X1 X2", "p.ngc:7:7: ", "found a second X word (the first is at column 4)"},
      {"G1 (unclosed", "p.ngc:7:4: ", "with no ')' before the end of the line"},
      {"G1 (a (b))", "p.ngc:7:7: ", "found '(' inside the comment opened at column 4"},
      {"G1 X#1", "p.ngc:7:5: ", "found 'X'"},  // X followed by '#': no number
      {"#1=2", "p.ngc:7:1: ", "parameters and expressions are not supported"},
      {"G1.55", "p.ngc:7:1: ", "found G1.55; expected a G code such as G1 or G90.1"},
      {"M3.5", "p.ngc:7:1: ", "found M3.5; expected an M code such as M3"},
      {"X1 N10", "p.ngc:7:4: ", "found an N line number after other words"},
      {"G1 @", "p.ngc:7:4: ", "found '@'; expected a word"},
      {"/G1 X1", "p.ngc:7:1: ", "block delete is not supported"},
      {"O1000 G1", "p.ngc:7:7: ", "expected the O number alone on its line"},
      {"G0 % X1", "p.ngc:7:4: ", "found '%' after words"},
  };
  for (const auto& c : cases) {
    const std::string e = error_of(c.line);
    EXPECT_EQ(e.rfind(c.prefix, 0), 0u) << c.line << " -> " << e;
    if (c.line != "G1 X#1") {
      EXPECT_NE(e.find(c.words), std::string::npos) << c.line << " -> " << e;
    }
  }
  EXPECT_NE(error_of("G1 X#1").find("found '#' after X; expected a number"), std::string::npos);
}

TEST(Parser, ErrorCarriesItsPlace) {
  try {
    parse("G1 Y", 12);
    FAIL();
  } catch (const GcodeError& e) {
    EXPECT_EQ(e.line(), 12);
    EXPECT_EQ(e.column(), 5);
    EXPECT_EQ(std::string(e.what()), "p.ngc:12:5: " + e.message());
  }
}

TEST(Parser, SplitsLinesAtNewlinesDroppingCarriageReturns) {
  std::vector<std::pair<std::string, int>> lines;
  for_each_line("G0 X1\r\n\nG1 Y2", [&](std::string_view l, int n) { lines.emplace_back(std::string(l), n); });
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[0], (std::pair<std::string, int>{"G0 X1", 1}));
  EXPECT_EQ(lines[1], (std::pair<std::string, int>{"", 2}));
  EXPECT_EQ(lines[2], (std::pair<std::string, int>{"G1 Y2", 3}));
  int count = 0;
  for_each_line("", [&](std::string_view, int) { ++count; });
  EXPECT_EQ(count, 0);
}

TEST(Parser, ABlockIsReusedWithoutLeftovers) {
  Block b;
  const Parser p("p.ngc");
  p.parse_line("N5 G1 X1 M3 (c)", 1, b);
  p.parse_line("Y2", 2, b);
  EXPECT_EQ(b.n, -1);
  EXPECT_EQ(b.g_count, 0);
  EXPECT_EQ(b.m_count, 0);
  EXPECT_FALSE(b.has('X'));
  EXPECT_TRUE(b.comment.empty());
  EXPECT_EQ(b.line, 2);
}

}  // namespace
