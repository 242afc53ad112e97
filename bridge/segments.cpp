#include "bridge/segments.hpp"

#include "gcode/parser.hpp"

namespace hybridctl::bridge {
namespace {

bool is_percent(std::string_view text) {
  while (!text.empty() && (text.back() == ' ' || text.back() == '\t' || text.back() == '\r')) text.remove_suffix(1);
  while (!text.empty() && (text.front() == ' ' || text.front() == '\t')) text.remove_prefix(1);
  return text == "%";
}

// nullopt when the line does not parse (LinuxCNC will say what is wrong with it).
std::optional<gcode::Block> parse(std::string_view text) {
  static const gcode::Parser parser("segment");
  gcode::Block block;
  try {
    parser.parse_line(text, 1, block);
  } catch (const gcode::GcodeError&) {
    return std::nullopt;
  }
  return block;
}

}  // namespace

std::string segment_file_text(const Segment& segment) {
  std::string text = "%\n";
  for (const std::string& line : segment.lines) {
    text += is_percent(line) ? "(%)" : line;
    text += '\n';
  }
  text += "%\n";
  return text;
}

std::uint32_t program_line(const Segment& segment, int file_line) {
  if (file_line < 2) return 0;
  const std::uint32_t index = std::uint32_t(file_line - 2);
  if (index >= segment.lines.size()) return segment.last_line();
  return segment.first_line + index;
}

std::uint32_t outputs_after(std::string_view text, std::uint32_t outputs_before) {
  const std::optional<gcode::Block> block = parse(text);
  if (!block || !block->has('P')) return outputs_before;
  const int output = int(block->value('P'));
  if (output < 0 || output > 31) return outputs_before;
  std::uint32_t outputs = outputs_before;
  for (int k = 0; k < block->m_count; ++k) {
    const int m = block->m[std::size_t(k)].value;
    if (m == 62 || m == 64) outputs |= 1u << output;
    if (m == 63 || m == 65) outputs &= ~(1u << output);
  }
  return outputs;
}

int stop_code(std::string_view text) {
  const std::optional<gcode::Block> block = parse(text);
  if (!block) return -1;
  for (int k = 0; k < block->m_count; ++k) {
    const int m = block->m[std::size_t(k)].value;
    if (m == 0 || m == 1) return m;
  }
  return -1;
}

bool moves(std::string_view text) {
  const std::optional<gcode::Block> block = parse(text);
  return block && (block->has('X') || block->has('Y') || block->has('Z'));
}

bool program_end(std::string_view text) {
  const std::optional<gcode::Block> block = parse(text);
  if (!block) return false;
  for (int k = 0; k < block->m_count; ++k) {
    const int m = block->m[std::size_t(k)].value;
    if (m == 2 || m == 30) return true;
  }
  return false;
}

bool safe_start(std::string_view text) {
  if (is_percent(text)) return true;
  const std::optional<gcode::Block> block = parse(text);
  if (!block) return false;
  for (int k = 0; k < block->g_count; ++k)
    if (block->g[std::size_t(k)].value == 0) return true;
  for (int k = 0; k < block->m_count; ++k)
    if (block->m[std::size_t(k)].value == 6) return true;
  return false;
}

void SegmentFeeder::add_lines(std::uint32_t first_line, std::string_view payload) {
  std::uint32_t number = first_line;
  gcode::for_each_line(payload, [&](std::string_view text, int) { pending_.push_back({number++, std::string(text)}); });
}

std::optional<Segment> SegmentFeeder::next_segment(std::uint32_t program_lines) {
  std::size_t cut = 0;  // lines in the segment; 0: no safe point yet
  std::uint32_t outputs = outputs_;
  std::uint32_t outputs_at_cut = outputs_;
  for (std::size_t i = 0; i < pending_.size(); ++i) {
    outputs = outputs_after(pending_[i].text, outputs);
    const bool last = pending_[i].number >= program_lines;
    const bool before_safe_start = i + 1 < pending_.size() && safe_start(pending_[i + 1].text);
    if (last || (outputs == 0 && before_safe_start)) {
      cut = i + 1;
      outputs_at_cut = outputs;
    }
  }
  if (cut == 0) return std::nullopt;
  Segment segment;
  segment.first_line = pending_.front().number;
  segment.outputs_at_start = outputs_;
  for (std::size_t i = 0; i < cut; ++i) segment.lines.push_back(std::move(pending_[i].text));
  pending_.erase(pending_.begin(), pending_.begin() + std::ptrdiff_t(cut));
  outputs_ = outputs_at_cut;
  return segment;
}

void SegmentFeeder::requeue(const Segment& segment, std::uint32_t from_line) {
  if (segment.lines.empty() || from_line > segment.last_line()) return;
  if (from_line < segment.first_line) from_line = segment.first_line;
  std::uint32_t outputs = segment.outputs_at_start;
  const std::size_t from = from_line - segment.first_line;
  for (std::size_t i = 0; i < from; ++i) outputs = outputs_after(segment.lines[i], outputs);
  for (std::size_t i = segment.lines.size(); i-- > from;)
    pending_.push_front({segment.first_line + std::uint32_t(i), segment.lines[i]});
  outputs_ = outputs;
}

void SegmentFeeder::clear() {
  pending_.clear();
  outputs_ = 0;
}

}  // namespace hybridctl::bridge
