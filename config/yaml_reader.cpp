#include "config/yaml_reader.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>

namespace hybridctl::config::detail {

// ---------------------------------------------------------------- DiagnosticSink

void DiagnosticSink::error(const YAML::Mark& at, std::string message) {
  if (kept_.size() >= kMaxKept) {
    ++dropped_;
    return;
  }
  const bool known = !at.is_null() && at.line >= 0 && at.column >= 0;
  kept_.push_back(Diagnostic{file_, known ? at.line + 1 : 1, known ? at.column + 1 : 1, std::move(message)});
}

std::vector<Diagnostic> DiagnosticSink::take_sorted() {
  std::stable_sort(kept_.begin(), kept_.end(), [](const Diagnostic& a, const Diagnostic& b) {
    return a.line != b.line ? a.line < b.line : a.column < b.column;
  });
  std::vector<Diagnostic> out = std::move(kept_);
  kept_.clear();
  if (out.size() > kMaxShown || dropped_ > 0) {
    const std::size_t hidden = out.size() - std::min(out.size(), kMaxShown) + dropped_;
    out.resize(std::min(out.size(), kMaxShown));
    out.push_back(Diagnostic{file_, 0, 0,
                             "... and " + std::to_string(hidden) + " more problems not shown; fix these first"});
  }
  return out;
}

// ---------------------------------------------------------------- text helpers

std::string printable(std::string_view text) {
  constexpr std::size_t kMaxShownChars = 60;
  std::string out;
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (out.size() >= kMaxShownChars) {
      out += "...";
      break;
    }
    const auto c = static_cast<unsigned char>(text[i]);
    if (c < 0x20 || c == 0x7f) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", c);
      out += buf;
    } else {
      out += static_cast<char>(c);
    }
  }
  return out;
}

namespace {

bool is_quoted(const YAML::Node& node) { return node.Tag() == "!"; }

std::optional<double> parse_double(std::string_view text) {
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  if (text.empty() || text.front() == '+') return std::nullopt;
  double value = 0.0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size()) return std::nullopt;
  return value;
}

std::optional<long long> parse_integer(std::string_view text) {
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  if (text.empty() || text.front() == '+') return std::nullopt;
  long long value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size()) return std::nullopt;
  return value;
}

char lower(char c) { return (c >= 'A' && c <= 'Z') ? char(c - 'A' + 'a') : c; }

}  // namespace

std::string describe(const YAML::Node& node) {
  switch (node.Type()) {
    case YAML::NodeType::Map: return "a mapping";
    case YAML::NodeType::Sequence: return "a list";
    case YAML::NodeType::Null: return "nothing";
    case YAML::NodeType::Undefined: return "nothing";
    case YAML::NodeType::Scalar: break;
  }
  const std::string& text = node.Scalar();
  if (is_quoted(node)) return "the quoted string '" + printable(text) + "'";
  const auto number = parse_double(text);
  if (number && std::isfinite(*number)) return printable(text);
  return "'" + printable(text) + "'";
}

std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      const std::size_t substitute = diagonal + (lower(a[i - 1]) == lower(b[j - 1]) ? 0 : 1);
      row[j] = std::min({above + 1, row[j - 1] + 1, substitute});
      diagonal = above;
    }
  }
  return row[b.size()];
}

std::string join(const std::vector<std::string_view>& words, std::string_view separator) {
  std::string out;
  for (std::size_t i = 0; i < words.size(); ++i) {
    if (i) out += separator;
    out += words[i];
  }
  return out;
}

namespace {

/// "" or " (did you mean 'x'?)" for the closest word within edit distance 2. A word that
/// would have to be replaced entirely ("up" for "+X") is no suggestion.
std::string suggestion(std::string_view word, const std::vector<std::string_view>& choices) {
  constexpr std::size_t kMaxSuggestionDistance = 2;
  std::string_view best;
  std::size_t best_distance = kMaxSuggestionDistance + 1;
  if (word.size() > 64) return {};
  for (auto c : choices) {
    const std::size_t d = edit_distance(word, c);
    if (d < best_distance && d < c.size()) {
      best_distance = d;
      best = c;
    }
  }
  if (best.empty()) return {};
  return " (did you mean '" + std::string(best) + "'?)";
}

std::string prefix(const std::string& path) { return path.empty() ? std::string() : path + ": "; }

std::string child_path(const std::string& parent, std::string_view key) {
  return parent.empty() ? std::string(key) : parent + "." + std::string(key);
}

}  // namespace

void report_bad_choice(DiagnosticSink& sink, const Value& v, const std::vector<std::string_view>& choices) {
  std::string message = prefix(v.path) + "expected one of " + join(choices) + ", got " + describe(v.node);
  if (v.node.IsScalar()) message += suggestion(v.node.Scalar(), choices);
  sink.error(v.mark, std::move(message));
}

// ---------------------------------------------------------------- MapReader

MapReader::MapReader(DiagnosticSink& sink, const Value& v, std::vector<std::string_view> allowed)
    : sink_(sink), self_(v) {
  if (!v.node.IsMap()) {
    std::string expected = allowed.empty() ? "expected a mapping" : "expected a mapping with keys " + join(allowed);
    sink_.error(v.mark, prefix(v.path) + expected + ", got " + describe(v.node));
    return;
  }
  ok_ = true;
  for (auto it = v.node.begin(); it != v.node.end(); ++it) {
    const YAML::Node key = it->first;
    const YAML::Node value = it->second;
    const YAML::Mark key_mark = key.Mark().is_null() ? v.mark : key.Mark();
    if (!key.IsScalar()) {
      sink_.error(key_mark, prefix(v.path) + "expected a key name, got " + describe(key) + " as a key");
      continue;
    }
    const std::string& name = key.Scalar();
    if (!allowed.empty() && std::find(allowed.begin(), allowed.end(), name) == allowed.end()) {
      sink_.error(key_mark, prefix(v.path) + "unknown key '" + printable(name) + "'" + suggestion(name, allowed) +
                                "; expected one of " + join(allowed));
      continue;
    }
    if (const Field* first = find(name)) {
      sink_.error(key_mark, child_path(v.path, printable(name)) + ": duplicate key, first given at line " +
                                std::to_string(first->key_mark.line + 1));
      continue;
    }
    // An empty value (`key:`) has the place of the next token; point at its key instead.
    const YAML::Mark value_mark = (value.IsNull() || value.Mark().is_null()) ? key_mark : value.Mark();
    fields_.push_back(Field{name, key_mark, Value{value, child_path(v.path, printable(name)), value_mark}});
  }
}

const MapReader::Field* MapReader::find(std::string_view key) const {
  for (const auto& f : fields_)
    if (f.key == key) return &f;
  return nullptr;
}

const MapReader::Field* MapReader::require(std::string_view key, std::string_view why) {
  const Field* f = find(key);
  if (!f && ok_) {
    std::string message = prefix(self_.path) + "missing required field '" + std::string(key) + "'";
    if (!why.empty()) message += " (" + std::string(why) + ")";
    sink_.error(self_.mark, std::move(message));
  }
  return f;
}

// ---------------------------------------------------------------- scalar readers

std::optional<std::vector<Value>> read_list(DiagnosticSink& sink, const Value& v, std::string_view of_what) {
  if (!v.node.IsSequence()) {
    sink.error(v.mark, prefix(v.path) + "expected a list of " + std::string(of_what) + ", got " + describe(v.node));
    return std::nullopt;
  }
  std::vector<Value> items;
  std::size_t i = 0;
  for (auto it = v.node.begin(); it != v.node.end(); ++it, ++i) {
    const YAML::Node item = *it;
    const YAML::Mark mark = item.Mark().is_null() ? v.mark : item.Mark();
    items.push_back(Value{item, v.path + "[" + std::to_string(i) + "]", mark});
  }
  return items;
}

std::optional<double> read_number(DiagnosticSink& sink, const Value& v, Quantity q, Bound bound) {
  std::optional<double> number;
  if (v.node.IsScalar() && !is_quoted(v.node)) number = parse_double(v.node.Scalar());
  if (!number || !std::isfinite(*number)) {
    sink.error(v.mark, prefix(v.path) + "expected a number in " + q.unit + ", got " + describe(v.node));
    return std::nullopt;
  }
  if (bound == Bound::Positive && !(*number > 0.0)) {
    sink.error(v.mark, prefix(v.path) + "expected a positive " + q.noun + " in " + q.unit + ", got " + describe(v.node));
    return std::nullopt;
  }
  if (bound == Bound::NonNegative && !(*number >= 0.0)) {
    sink.error(v.mark,
               prefix(v.path) + "expected a non-negative " + q.noun + " in " + q.unit + ", got " + describe(v.node));
    return std::nullopt;
  }
  return number;
}

std::optional<int> read_integer(DiagnosticSink& sink, const Value& v, long min, long max, std::string_view expected) {
  std::optional<long long> number;
  if (v.node.IsScalar() && !is_quoted(v.node)) number = parse_integer(v.node.Scalar());
  if (!number || *number < min || *number > max) {
    sink.error(v.mark, prefix(v.path) + "expected " + std::string(expected) + ", got " + describe(v.node));
    return std::nullopt;
  }
  return static_cast<int>(*number);
}

std::optional<std::string> read_string(DiagnosticSink& sink, const Value& v, std::string_view expected) {
  if (!v.node.IsScalar() || v.node.Scalar().empty()) {
    sink.error(v.mark, prefix(v.path) + "expected " + std::string(expected) + ", got " +
                           (v.node.IsScalar() ? std::string("an empty string") : describe(v.node)));
    return std::nullopt;
  }
  return v.node.Scalar();
}

std::optional<bool> read_bool(DiagnosticSink& sink, const Value& v) {
  if (v.node.IsScalar() && !is_quoted(v.node)) {
    const std::string& s = v.node.Scalar();
    if (s == "true" || s == "yes") return true;
    if (s == "false" || s == "no") return false;
  }
  sink.error(v.mark, prefix(v.path) + "expected true or false, got " + describe(v.node));
  return std::nullopt;
}

std::optional<Range> read_range(DiagnosticSink& sink, const Value& v, Quantity q) {
  const std::string expected = std::string("expected [min, max] in ") + q.unit;
  if (!v.node.IsSequence() || v.node.size() != 2) {
    std::string got = v.node.IsSequence() ? "a list of " + std::to_string(v.node.size()) : describe(v.node);
    sink.error(v.mark, prefix(v.path) + expected + ", got " + got);
    return std::nullopt;
  }
  const auto items = read_list(sink, v, "numbers");
  const auto lo = read_number(sink, (*items)[0], q, Bound::Any);
  const auto hi = read_number(sink, (*items)[1], q, Bound::Any);
  if (!lo || !hi) return std::nullopt;
  if (!(*lo < *hi)) {
    sink.error(v.mark, prefix(v.path) + expected + " with min < max, got [" + describe((*items)[0].node) + ", " +
                           describe((*items)[1].node) + "]");
    return std::nullopt;
  }
  return Range{*lo, *hi};
}

}  // namespace hybridctl::config::detail
