// The bridge's segment feeder (bridge/segments.hpp): where a streamed program is cut into
// the files LinuxCNC runs, and how LinuxCNC's file lines map back to program lines.

#include "bridge/segments.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace hybridctl::bridge {
namespace {

std::string payload(const std::vector<std::string>& lines) {
  std::string text;
  for (const std::string& l : lines) text += l + "\n";
  return text;
}

TEST(SegmentFeeder, CutsOnlyBeforeARapidWithEveryOutputOff) {
  SegmentFeeder feeder;
  feeder.add_lines(1, payload({"G21 G90 G54", "G0 X0 Y0 Z10", "M64 P0", "G1 X5 F800", "G1 Y5", "M65 P0", "G0 Z20",
                               "G1 X0"}));
  const auto s = feeder.next_segment(100);
  ASSERT_TRUE(s);
  // Line 1 before the first G0 is a cut too, but the feeder takes the last one: lines 1..6.
  EXPECT_EQ(s->first_line, 1u);
  EXPECT_EQ(s->last_line(), 6u);
  EXPECT_EQ(feeder.next_line(), 7u);
  // Lines 7-8: no safe point after them yet (the program goes on).
  EXPECT_FALSE(feeder.next_segment(100));
}

TEST(SegmentFeeder, NeverCutsWhileDepositing) {
  SegmentFeeder feeder;
  feeder.add_lines(1, payload({"M64 P0", "G1 X1", "G0 X2", "G1 X3", "G0 X4"}));
  EXPECT_FALSE(feeder.next_segment(10)) << "every G0 here comes while the laser is on";
  feeder.add_lines(6, payload({"M65 P0", "G0 Z10"}));
  const auto s = feeder.next_segment(10);
  ASSERT_TRUE(s);
  EXPECT_EQ(s->last_line(), 6u);
}

TEST(SegmentFeeder, TheProgramsLastLineIsAlwaysACut) {
  SegmentFeeder feeder;
  feeder.add_lines(1, payload({"G1 X1", "M2", "%"}));
  const auto s = feeder.next_segment(3);
  ASSERT_TRUE(s);
  EXPECT_EQ(s->last_line(), 3u);
  EXPECT_TRUE(feeder.empty());
}

TEST(SegmentFeeder, RequeuedLinesComeBackWithTheirOutputState) {
  SegmentFeeder feeder;
  feeder.add_lines(1, payload({"G0 X0", "M64 P0", "G1 X1", "G1 X2", "M65 P0", "G0 Z5", "G1 X0", "M2"}));
  auto s = feeder.next_segment(8);
  ASSERT_TRUE(s);
  ASSERT_EQ(s->last_line(), 8u);
  // LinuxCNC stopped after line 3 (e-stop): lines 4.. run again, the laser still on
  // before line 4, so the next cut is after line 5 (M65), before the G0.
  feeder.requeue(*s, 4);
  EXPECT_EQ(feeder.next_line(), 4u);
  s = feeder.next_segment(8);
  ASSERT_TRUE(s);
  EXPECT_EQ(s->first_line, 4u);
  EXPECT_EQ(s->outputs_at_start, 1u);
  EXPECT_EQ(s->last_line(), 8u);
}

TEST(SegmentFile, WrapsTheLinesInPercentLinesAndMapsFileLinesBack) {
  Segment s;
  s.first_line = 41;
  s.lines = {"%", "G0 X1", "M2"};
  EXPECT_EQ(segment_file_text(s), "%\n(%)\nG0 X1\nM2\n%\n");
  EXPECT_EQ(program_line(s, 0), 0u);  // LinuxCNC: no line yet
  EXPECT_EQ(program_line(s, 1), 0u);  // the wrapper
  EXPECT_EQ(program_line(s, 2), 41u);
  EXPECT_EQ(program_line(s, 4), 43u);
  EXPECT_EQ(program_line(s, 5), 43u);  // the closing wrapper: the segment's end
}

TEST(SegmentLines, ReadOutputsStopsAndSafeStarts) {
  EXPECT_EQ(outputs_after("M64 P0", 0), 1u);
  EXPECT_EQ(outputs_after("M62 P2 (synced)", 1), 5u);
  EXPECT_EQ(outputs_after("M65 P0", 5), 4u);
  EXPECT_EQ(outputs_after("G1 X1 F100", 4), 4u);
  EXPECT_EQ(outputs_after("#1 = 2", 4), 4u) << "a line our parser does not read changes nothing";
  EXPECT_EQ(stop_code("M0"), 0);
  EXPECT_EQ(stop_code("M01 (check)"), 1);
  EXPECT_EQ(stop_code("M05"), -1);
  EXPECT_EQ(stop_code("M6 T1"), -1);
  EXPECT_TRUE(program_end("M2"));
  EXPECT_TRUE(program_end("M30 (end)"));
  EXPECT_FALSE(program_end("M3 S8000"));
  EXPECT_TRUE(moves("G53 G0 Z300"));
  EXPECT_FALSE(moves("M5"));
  EXPECT_TRUE(safe_start("G0 Z50"));
  EXPECT_TRUE(safe_start("T2 M6"));
  EXPECT_TRUE(safe_start("%"));
  EXPECT_FALSE(safe_start("G1 X0"));
  EXPECT_FALSE(safe_start("(comment)"));
}

}  // namespace
}  // namespace hybridctl::bridge
