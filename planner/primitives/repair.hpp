#pragma once
// Deposits local to a repair (docs/support.md, "Repair"): when every plan starts from a
// given stock (a worn part, `plan --stock`), a head's whole-part U-AM or O-AM deposits all
// the design that is missing and its overfill everywhere, also where the head cannot reach
// to mill it back (under an overhang). The paper's fine-graining restricts a capability's
// primitive to the neighbourhood of the atoms it should make: here, each head's U-AM and
// O-AM cut to the missing region grown by the head's bead and the tolerance, and cut again
// to what builds on the stock.

#include <vector>

#include "config/machine.hpp"
#include "geometry/solid.hpp"
#include "planner/primitives/machine_primitives.hpp"

namespace hybridctl::planner {

// The local deposits for `stock` among `primitives` (whole-part U-AM and O-AM of the
// machine's heads); none when the stock lacks nothing of the design. Names are left to
// the caller.
std::vector<Primitive> repair_primitives(const config::Machine& machine, const geometry::Solid& design,
                                         const geometry::Solid& stock, double tolerance, const geometry::IndexBox& domain,
                                         const std::vector<Primitive>& primitives);

}  // namespace hybridctl::planner
