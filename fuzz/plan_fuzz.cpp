// Fuzz target: the plan.json reader (plan/plan_file.hpp: parse_plan_file, the in-memory
// form of read_plan_file) on arbitrary text, then the states each plan passes through
// (plan_states), as `hybridctl export` and `hybridctl run` do with a plan they read.
//
// The .vdb files a plan names are real: at start-up the target writes a small plan
// directory in $TMPDIR (design.vdb, primitives/P1.vdb .. P3.vdb on a 1 mm grid at the
// origin; the seed corpus's plan.json files name them) and removes it at exit. The JSON
// under test is not written there: it only stands at DIR/plan.json for the messages.
// Contract: parse_plan_file throws hybridctl::InputError (and nothing else) naming the file.

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <string_view>

#include "common/error.hpp"
#include "fuzz/fuzz_check.hpp"
#include "geometry/vdb_file.hpp"
#include "plan/plan_file.hpp"

namespace fs = std::filesystem;
namespace geometry = hybridctl::geometry;
namespace planner = hybridctl::planner;

namespace {

fs::path* plan_dir = nullptr;

void remove_plan_dir() {
  std::error_code ec;
  if (plan_dir) fs::remove_all(*plan_dir, ec);
}

geometry::Solid box(const geometry::Lattice& lattice, geometry::Index3 lo, geometry::Index3 hi) {
  return geometry::Solid::filled(lattice, {lo, hi});
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  const char* tmp = std::getenv("TMPDIR");
  std::string pattern = std::string(tmp && *tmp ? tmp : "/tmp") + "/hybridctl-plan-fuzz-XXXXXX";
  if (!::mkdtemp(pattern.data())) {
    std::perror("plan_fuzz: mkdtemp");
    std::abort();
  }
  plan_dir = new fs::path(pattern);
  std::atexit(remove_plan_dir);
  fs::create_directories(*plan_dir / "primitives");
  // The grid of the seeds: 1 mm voxels, origin 0, domain [0, 8)^3.
  const geometry::Lattice lattice{1.0, {0, 0, 0}};
  geometry::write_vdb(box(lattice, {2, 2, 0}, {6, 6, 4}), *plan_dir / "design.vdb", "design");
  geometry::write_vdb(box(lattice, {1, 1, 0}, {7, 7, 5}), *plan_dir / "primitives" / "P1.vdb", "P1");  // stock
  geometry::write_vdb(box(lattice, {2, 2, 0}, {6, 6, 6}), *plan_dir / "primitives" / "P2.vdb", "P2");  // u-am
  geometry::write_vdb(box(lattice, {0, 0, 4}, {8, 8, 8}), *plan_dir / "primitives" / "P3.vdb", "P3");  // sm-max
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const fs::path json_path = *plan_dir / "plan.json";
  plan::PlanFile file;
  try {
    file = plan::parse_plan_file(text, json_path);
  } catch (const hybridctl::InputError& e) {
    FUZZ_CHECK(std::string_view(e.what()).starts_with(plan_dir->string()), "a plan.json error names the file");
    return 0;
  }
  for (const plan::PlanFilePlan& plan : file.plans) {
    for (const plan::PlanFileAction& a : plan.actions)
      FUZZ_CHECK(a.primitive >= 0 && std::size_t(a.primitive) < file.primitives.size(),
                 "every action names one of the plan's primitives");
    const auto states = plan::plan_states(file, plan);
    FUZZ_CHECK(states.size() == plan.actions.size() + 1, "one state before the plan and one after each action");
  }
  return 0;
}
