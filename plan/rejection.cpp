#include "plan/rejection.hpp"

#include "common/number_text.hpp"

namespace hybridctl::plan {

std::string describe(const RejectionReason& r) {
  std::string out;
  if (r.action > 0) out += "action " + std::to_string(r.action);
  if (r.line > 0) out += std::string(out.empty() ? "" : ", ") + "line " + std::to_string(r.line);
  if (!out.empty()) out += ": ";
  out += r.message;
  if (r.where)
    out += " (at " + trimmed_number(r.where->x, 2) + ", " + trimmed_number(r.where->y, 2) + ", " +
           trimmed_number(r.where->z, 2) + " mm)";
  return out;
}

}  // namespace hybridctl::plan
