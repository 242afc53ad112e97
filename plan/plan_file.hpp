#pragma once
// A plan as the plan directory written by `hybridctl plan` holds it (docs/plan-format.md):
// the grid, the design, every primitive's region and the plans' action sequences, enough
// to replay any plan on the voxels and turn its actions into G-code. Read back from the
// directory, or made from the planning result in memory: the same value either way.

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "config/primitive_kind.hpp"
#include "geometry/mesh.hpp"
#include "geometry/solid.hpp"
#include "plan/planning_band.hpp"
#include "plan/rejection.hpp"

namespace hybridctl::plan {

using config::Mode;
using config::PrimitiveKind;

// The copy of the part's STL a plan directory holds beside plan.json, so that the design's
// real surface travels with the plan (exact verification, docs/verification.md).
inline constexpr const char* kDesignStl = "design.stl";

// plan.json's `version`: what this reader reads and the writer writes.
inline constexpr int kPlanFormatVersion = 1;

struct PlanFilePrimitive {
  std::string name;        // P1, P2, ...
  std::string label;
  PrimitiveKind kind = PrimitiveKind::File;
  Mode mode = Mode::Additive;
  std::string capability;  // head name, T<n>, stock name or file path
  std::string setup;       // empty for stocks and files
  int tool_number = 0;     // cutting tools
  geometry::Solid region;
  bool raw_stock() const { return kind == PrimitiveKind::RawStock; }
  friend bool operator==(const PlanFilePrimitive&, const PlanFilePrimitive&) = default;
};

struct PlanFileAction {
  int primitive = -1;  // index into PlanFile::primitives
  double volume = 0;   // mm^3 deposited or removed as planned
  double cost = 0;     // normalised
  friend bool operator==(const PlanFileAction&, const PlanFileAction&) = default;
};

struct PlanFilePlan {
  int rank = 0;
  std::string expression;
  double cost = 0;
  std::vector<PlanFileAction> actions;
  friend bool operator==(const PlanFilePlan&, const PlanFilePlan&) = default;
};

// A candidate plan that failed when executed (validation/), with its located reasons.
struct PlanFileRejected {
  std::string expression;
  double cost = 0;
  std::vector<PlanFileAction> actions;
  std::vector<RejectionReason> reasons;
  friend bool operator==(const PlanFileRejected&, const PlanFileRejected&) = default;
};

struct PlanFile {
  std::filesystem::path directory;
  std::string part;                        // relative to `directory` (older plans: as given)
  std::string machine_name, machine_file;  // machine_file relative to `directory` (older plans: as given)
  std::string machine_yaml;                // the machine file's text, embedded; empty in older plans
  std::string machine_hash;                // FNV-1a 64 of machine_yaml, 16 hex digits

  geometry::Lattice lattice;
  geometry::IndexBox domain;
  double tolerance = 0;  // mm, the part's, on the design's real surface (plan/planning_band.hpp)
  double band() const { return planning_band(tolerance, lattice.voxel_size); }  // mm, on the voxels
  geometry::Solid design;
  // The design's real surface: the plan directory's design.stl, else the part's STL it
  // names; empty for a design made on voxels (tests) or when neither file is there. Exact
  // verification measures against it and milling cuts to its flat faces.
  geometry::TriangleMesh design_mesh;
  std::vector<PlanFilePrimitive> primitives;
  std::vector<PlanFilePlan> plans;
  std::vector<PlanFileRejected> rejected;  // empty in older plans and when nothing was rejected
  // Solids compare by their voxels (geometry::Solid's ==).
  friend bool operator==(const PlanFile&, const PlanFile&) = default;
};


// Reads DIR/plan.json (or the plan.json given) and the .vdb files it names. Throws
// hybridctl::InputError naming the file and the JSON location of anything missing,
// mistyped or inconsistent (unknown version, a plan naming a primitive that does not
// exist, a .vdb on another grid).
PlanFile read_plan_file(const std::filesystem::path& plan_json_or_directory);
// The same from the text of a plan.json that stands at `json_path` (used in messages; the
// .vdb files are read from its directory, the file itself is not read).
PlanFile parse_plan_file(std::string_view json_text, const std::filesystem::path& json_path);

// The grid of a plan.json (or its directory) and how many primitives it has, without
// reading any .vdb: enough to size the memory its solids take before loading them.
struct PlanGrid {
  geometry::Lattice lattice;
  geometry::IndexBox domain;
  std::size_t primitives = 0;
};
PlanGrid read_plan_grid(const std::filesystem::path& plan_json_or_directory);

// `path` (absolute, or relative to the working directory) as plan.json in `directory`
// records it: relative to that directory, or absolute when no relative path leads there.
std::string path_from_plan_directory(const std::string& path, const std::filesystem::path& directory);

// A solid in memory as its .vdb reads back, on the plan's grid: a .vdb holds the voxels
// only, so the storage is what their bounding box needs, clipped to the domain.
geometry::Solid as_read_back(const geometry::Solid& s, const geometry::Lattice& lattice, const geometry::IndexBox& domain);

// The states a plan passes through on the voxels: states[0] is empty, states[k] the
// material after action k (AM unites, SM subtracts), clipped to the domain.
std::vector<geometry::Solid> plan_states(const PlanFile& file, const PlanFilePlan& plan);

}  // namespace hybridctl::plan
