#pragma once
// What `hybridctl report` does, shared with `plan --report` and `dry-run --report`: write
// the job report (report/report.hpp) and say what was written.

#include "report/report.hpp"

namespace hybridctl::cli {

// Writes the report and prints one line with its path, size and contents, and one with
// the snapshots. Throws what report::write_report throws.
void write_job_report(const report::ReportRequest& request);

}  // namespace hybridctl::cli
