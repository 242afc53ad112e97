#pragma once
// A refusal's places in a shop's words (docs/search.md, "Refusals in shop words"): for
// each region of air a refused or undecided verdict names, what it is (a closed space, the
// stock under the part, a narrow slot), why no instrument of the machine clears it (no
// direction reaches it, no setup from the one that does, no cutter that fits), and what
// would; for each region of the design, whether it is an overhang: over an underside of
// the STL that leans past the head's support.max_overhang, both angles said. The
// atom-level detail stays in the verdict's list and plan.json.

#include <string>
#include <vector>

#include "config/machine.hpp"
#include "planner/pipeline/planning.hpp"

namespace hybridctl::planner {

// One line per region the verdict names (a region that straddles the design: its air, then
// its design), in its order (the proof's heart first), at most `limit`, for the regions it
// can say it of with certainty: air closed in on every side, open only where the machine
// has no setup, or narrower than its smallest cutter; design no deposit lays, that the
// head's limit cuts from every setup, over an underside leaning past that limit. A closed
// space, a slot or an underside split among regions is said once. None for a part with
// plans, or a verdict that names no such region.
std::vector<std::string> refusal_in_shop_words(const config::Machine& machine, const PlanningResult& result,
                                               std::size_t limit = 4);

}  // namespace hybridctl::planner
