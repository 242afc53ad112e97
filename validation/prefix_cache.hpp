#pragma once
// Executed prefixes of plans, to resume from (docs/validation.md, "Cost"). The search
// offers many candidates that begin with the same actions; executing each from the raw
// stock again repeats the costliest part of validation (toolpaths and the simulation of
// the same actions). Execution is deterministic and an action depends only on the ones
// before it, so the state after a prefix that went right is all a candidate beginning
// with it needs to go on, and it ends exactly as it would from the raw stock.
//
//   auto cache = std::make_shared<validation::PrefixCache>();
//   planner::validate_by_execution(options, validation::plan_validator(machine, {}, cache), machine.name);
//   ... cache->stats().hits ...
//
// One cache serves one plan file, one machine and one set of ExecutionOptions (a plan
// validator's): the key is the primitives of the prefix alone. Given another file or
// machine, execute_plan empties it first.

#include <cstddef>
#include <memory>

namespace hybridctl::validation {

namespace detail {
struct PrefixCacheImpl;  // validation/execution.cpp
}

struct PrefixCacheStats {
  std::size_t lookups = 0;          // executions that asked the cache
  std::size_t hits = 0;             // ... and resumed from a prefix it held
  std::size_t resumed_actions = 0;  // actions not executed again, over all hits
  std::size_t stored = 0;           // prefixes kept, over the cache's life
  std::size_t evicted = 0;          // prefixes dropped to stay under the cap
  std::size_t entries = 0;          // prefixes held now
  std::size_t bytes = 0;            // their estimated size now (solids, programs, lines)
};

class PrefixCache {
 public:
  // A prefix holds the simulated stock and the regions protected from cuts (a few voxel
  // solids over the plan's domain) and the programs so far: 2-3.5 MB on the bundled parts
  // at 0.5 mm, so 256 MiB keeps about 80-100.
  static constexpr std::size_t kDefaultMaxBytes = std::size_t(256) << 20;

  // Least recently used prefixes are dropped once the total passes `max_bytes`; a prefix
  // larger than that is not kept.
  explicit PrefixCache(std::size_t max_bytes = kDefaultMaxBytes);
  ~PrefixCache();
  PrefixCache(const PrefixCache&) = delete;
  PrefixCache& operator=(const PrefixCache&) = delete;

  const PrefixCacheStats& stats() const;
  std::size_t max_bytes() const;
  void clear();

  detail::PrefixCacheImpl& impl() { return *impl_; }  // for execution.cpp

 private:
  std::unique_ptr<detail::PrefixCacheImpl> impl_;
};

}  // namespace hybridctl::validation
