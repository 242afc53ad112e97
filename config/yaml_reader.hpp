#pragma once
// Typed, reporting access to a yaml-cpp document (internal to config/).
//
// Every reader checks one value, reports what is wrong through a DiagnosticSink (with the
// value's place and dotted path, e.g. "tools[1].diameter") and returns std::nullopt on a
// problem, so the loader can go on and report every problem in one pass.

#include <yaml-cpp/yaml.h>

#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "config/diagnostic.hpp"
#include "config/machine.hpp"

namespace hybridctl::config::detail {

/// Collects diagnostics; keeps at most kMaxKept so hostile input cannot exhaust memory.
class DiagnosticSink {
 public:
  static constexpr std::size_t kMaxKept = 1000;   ///< collected before sorting
  static constexpr std::size_t kMaxShown = 100;   ///< reported after sorting

  explicit DiagnosticSink(std::string file) : file_(std::move(file)) {}

  /// `at` is a 0-based yaml-cpp mark; a null mark is reported as 1:1.
  void error(const YAML::Mark& at, std::string message);
  bool empty() const { return kept_.empty() && dropped_ == 0; }
  /// Problems reported so far; compare before and after reading an item to skip
  /// cross-checks on items that already have problems.
  std::size_t count() const { return kept_.size() + dropped_; }
  /// The diagnostics in file order (stable for equal places), at most kMaxShown + 1.
  std::vector<Diagnostic> take_sorted();

 private:
  std::string file_;
  std::vector<Diagnostic> kept_;
  std::size_t dropped_ = 0;
};

/// A value in the document: the node, its dotted path and where to point at it.
struct Value {
  YAML::Node node;
  std::string path;
  YAML::Mark mark;
};

/// What a number measures, for messages: "expected a positive <noun> in <unit>".
struct Quantity {
  const char* noun;
  const char* unit;
};
inline constexpr Quantity kLength{"length", "mm"};
inline constexpr Quantity kFeed{"feed", "mm/min"};
inline constexpr Quantity kAcceleration{"acceleration", "mm/s²"};
inline constexpr Quantity kAngle{"angle", "degrees"};
inline constexpr Quantity kAngularFeed{"feed", "deg/min"};
inline constexpr Quantity kAngularAcceleration{"acceleration", "deg/s²"};
inline constexpr Quantity kSpindleSpeed{"spindle speed", "rpm"};
inline constexpr Quantity kVolume{"volume", "mm³"};
inline constexpr Quantity kCost{"cost", "cost units"};
inline constexpr Quantity kCostFactor{"cost factor", "cost units per mm³"};
inline constexpr Quantity kPower{"power value", "the controller's power unit"};
inline constexpr Quantity kMoney{"amount", "money"};
inline constexpr Quantity kHourlyRate{"rate", "money per hour"};
inline constexpr Quantity kVolumeRate{"rate", "mm³/min"};
inline constexpr Quantity kSeconds{"duration", "s"};
inline constexpr Quantity kMinutes{"duration", "min"};
inline constexpr Quantity kDensity{"density", "g/cm³"};
inline constexpr Quantity kPricePerKg{"price", "money per kg"};
inline constexpr Quantity kFraction{"fraction", "0 < f <= 1"};

enum class Bound { Any, Positive, NonNegative };

/// How a value is shown in a message: -3, 'ten', the string '10', a mapping, a list, nothing.
std::string describe(const YAML::Node& node);
/// Printable, length-limited text for messages.
std::string printable(std::string_view text);
/// Levenshtein distance (ASCII case-insensitive).
std::size_t edit_distance(std::string_view a, std::string_view b);
/// "a, b, c"
std::string join(const std::vector<std::string_view>& words, std::string_view separator = ", ");

/// A mapping whose keys have been checked: every key is a scalar, none is repeated, and
/// (unless `allowed` is empty) each is one of `allowed`; unknown keys are reported with a
/// "did you mean" within edit distance 2.
class MapReader {
 public:
  struct Field {
    std::string key;
    YAML::Mark key_mark;
    Value value;
  };

  /// Reports "expected a mapping with keys ..." when `v` is not a mapping (then ok() is false).
  MapReader(DiagnosticSink& sink, const Value& v, std::vector<std::string_view> allowed);

  bool ok() const { return ok_; }
  const Value& value() const { return self_; }
  const std::vector<Field>& fields() const { return fields_; }
  const Field* find(std::string_view key) const;
  /// Like find, but reports "missing required field" at the mapping when absent.
  const Field* require(std::string_view key, std::string_view why = {});

 private:
  DiagnosticSink& sink_;
  Value self_;
  bool ok_ = false;
  std::vector<Field> fields_;
};

/// The items of a list, each with path "<path>[i]". Reports a non-list.
std::optional<std::vector<Value>> read_list(DiagnosticSink& sink, const Value& v, std::string_view of_what);

std::optional<double> read_number(DiagnosticSink& sink, const Value& v, Quantity q, Bound bound);
/// An integer in [min, max]; `expected` completes "expected <expected>", e.g. "a positive tool number".
std::optional<int> read_integer(DiagnosticSink& sink, const Value& v, long min, long max, std::string_view expected);
/// A non-empty string; `expected` completes "expected <expected>".
std::optional<std::string> read_string(DiagnosticSink& sink, const Value& v, std::string_view expected);
std::optional<bool> read_bool(DiagnosticSink& sink, const Value& v);
/// [min, max] with min < max.
std::optional<Range> read_range(DiagnosticSink& sink, const Value& v, Quantity q);

/// One of a fixed list of words.
template <class E>
std::optional<E> read_enum(DiagnosticSink& sink, const Value& v,
                           const std::vector<std::pair<std::string_view, E>>& choices);

// --- implementation of the template ---

/// Reports "expected one of <choices>, got <x>" with a "did you mean" when close.
void report_bad_choice(DiagnosticSink& sink, const Value& v, const std::vector<std::string_view>& choices);

template <class E>
std::optional<E> read_enum(DiagnosticSink& sink, const Value& v,
                           const std::vector<std::pair<std::string_view, E>>& choices) {
  if (v.node.IsScalar()) {
    for (const auto& [word, e] : choices)
      if (v.node.Scalar() == word) return e;
  }
  std::vector<std::string_view> words;
  for (const auto& c : choices) words.push_back(c.first);
  report_bad_choice(sink, v, words);
  return std::nullopt;
}

}  // namespace hybridctl::config::detail
