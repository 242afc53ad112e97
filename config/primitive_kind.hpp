#pragma once
// The kinds of primitive and how a primitive changes the part: the vocabulary the machine
// file, the planner and plan.json share.

#include <optional>
#include <string_view>
#include <utility>

namespace hybridctl::config {

/// The kinds of primitive (docs/architecture.md, "The planning core"): what a plan starts
/// from, the four the planner derives from a head or a tool (the ones a machine file's
/// `primitives:` lists name), and one given as a file. The one definition the planner,
/// plan.json and everything that reads plans use.
enum class PrimitiveKind {
  RawStock,  ///< "raw-stock": a stock a plan starts from
  UAm,       ///< "u-am": maximal depositable region inside the design
  OAm,       ///< "o-am": conservative overfill
  SmMax,     ///< "sm-max": maximal removable region that never cuts the design
  SmCons,    ///< "sm-cons": conservative over-cut
  File,      ///< "file": a region given as a file (`plan --primitive`)
};

/// How a primitive changes the part: additive unites its region with it, subtractive
/// removes its region (the paper's S -> S u P and S -> S n complement(P)).
enum class Mode { Additive, Subtractive };

// Names as written in the machine file and plan.json.
inline constexpr std::pair<PrimitiveKind, std::string_view> kPrimitiveKindNames[] = {
    {PrimitiveKind::RawStock, "raw-stock"}, {PrimitiveKind::UAm, "u-am"},       {PrimitiveKind::OAm, "o-am"},
    {PrimitiveKind::SmMax, "sm-max"},       {PrimitiveKind::SmCons, "sm-cons"}, {PrimitiveKind::File, "file"}};

constexpr std::string_view to_string(PrimitiveKind k) {
  for (const auto& [kind, name] : kPrimitiveKindNames)
    if (kind == k) return name;
  return "?";
}

constexpr std::string_view to_string(Mode m) { return m == Mode::Additive ? "additive" : "subtractive"; }

// The kind a name stands for ("raw-stock", "u-am", ...); none for any other name.
constexpr std::optional<PrimitiveKind> primitive_kind_named(std::string_view name) {
  for (const auto& [kind, kind_name] : kPrimitiveKindNames)
    if (kind_name == name) return kind;
  return std::nullopt;
}

}  // namespace hybridctl::config
