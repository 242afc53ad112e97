#pragma once
// --memory-budget SIZE: how much memory a command's grids may take (geometry/
// memory_estimate.hpp); default half the physical memory.

#include <CLI/CLI.hpp>

#include <cstdint>
#include <string>

#include "geometry/memory_estimate.hpp"

namespace hybridctl::cli {

inline CLI::Option* add_memory_budget_option(CLI::App* cmd, std::string& into) {
  return cmd->add_option("--memory-budget", into,
                         "Memory the voxel grids may take, e.g. 8G or 500M (default: half the physical memory); a voxel "
                         "size needing more is refused up front (exit 3)");
}

// 0 when not given (the default budget).
inline std::uint64_t memory_budget(const std::string& text) {
  return text.empty() ? 0 : geometry::parse_memory_size(text, "--memory-budget");
}

}  // namespace hybridctl::cli
