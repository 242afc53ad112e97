#pragma once
// A human summary of a machine, as printed by `hybridctl machine check`.

#include <string>

#include "config/machine.hpp"

namespace hybridctl::config {

/// Several lines, each ending in '\n': envelope, heads, tools, setups, raw stocks,
/// transports, G-code dialect, planning defaults.
std::string summarize(const Machine& machine);

}  // namespace hybridctl::config
