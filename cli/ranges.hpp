#pragma once
// Numeric option ranges said as a person writes them: "--voxel must be greater than 0
// (got 0)", not CLI11's "Value 0 not in range 0.000000 to 1797693134862315708145...".

#include <CLI/CLI.hpp>

#include <cstdio>
#include <string>

namespace hybridctl::cli {

namespace ranges_detail {
inline std::string number(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.12g", v);
  return b;
}
// The option's value as a number, or the text when it is none.
inline bool parse(const std::string& text, double& v) {
  try {
    std::size_t used = 0;
    v = std::stod(text, &used);
    return used == text.size();
  } catch (const std::exception&) {
    return false;
  }
}
inline CLI::Validator check(std::string description, std::function<bool(double)> ok, std::string rule) {
  return CLI::Validator(
      [ok = std::move(ok), rule = std::move(rule)](std::string& text) -> std::string {
        double v = 0;
        if (!parse(text, v)) return "must be a number (got '" + text + "')";
        return ok(v) ? std::string() : "must be " + rule + " (got " + text + ")";
      },
      std::move(description));
}
}  // namespace ranges_detail

inline CLI::Validator greater_than(double low) {
  return ranges_detail::check("> " + ranges_detail::number(low), [low](double v) { return v > low; },
                              "greater than " + ranges_detail::number(low));
}
inline CLI::Validator at_least(double low) {
  return ranges_detail::check(">= " + ranges_detail::number(low), [low](double v) { return v >= low; },
                              "at least " + ranges_detail::number(low));
}
inline CLI::Validator between(double low, double high) {
  return ranges_detail::check(ranges_detail::number(low) + ".." + ranges_detail::number(high),
                              [low, high](double v) { return v >= low && v <= high; },
                              "between " + ranges_detail::number(low) + " and " + ranges_detail::number(high));
}

// CLI11 says "--voxel: must be ..."; people write "--voxel must be ...".
inline std::string failure_message(const CLI::App* app, const CLI::Error& e) {
  std::string text = CLI::FailureMessage::simple(app, e);
  if (const auto at = text.find(": must be "); at != std::string::npos && text.rfind("--", at) != std::string::npos)
    text.erase(at, 1);
  return text;
}

}  // namespace hybridctl::cli
