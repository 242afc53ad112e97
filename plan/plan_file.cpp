#include "plan/plan_file.hpp"

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "common/error.hpp"
#include "geometry/vdb_file.hpp"
#include "plan/plan_machine.hpp"

namespace hybridctl::plan {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// A JSON value with its location, so every error says where.
class Node {
 public:
  Node(const json& j, std::string file, std::string pointer) : j_(j), file_(std::move(file)), pointer_(std::move(pointer)) {}

  [[noreturn]] void fail(const std::string& expected) const {
    throw InputError(file_ + ": " + (pointer_.empty() ? "/" : pointer_) + ": expected " + expected + ", found " +
                     (j_.is_null() ? std::string("nothing") : j_.dump().substr(0, 60)));
  }
  Node at(const std::string& key) const {
    if (!j_.is_object()) fail("an object");
    static const json missing;
    const auto it = j_.find(key);
    return Node(it == j_.end() ? missing : *it, file_, pointer_ + "/" + key);
  }
  Node at(std::size_t i) const { return Node(j_.at(i), file_, pointer_ + "/" + std::to_string(i)); }
  bool has(const std::string& key) const { return j_.is_object() && j_.contains(key); }
  std::size_t size() const {
    if (!j_.is_array()) fail("an array");
    return j_.size();
  }
  std::string str() const {
    if (!j_.is_string()) fail("a string");
    return j_.get<std::string>();
  }
  double number() const {
    if (!j_.is_number()) fail("a number");
    const double v = j_.get<double>();
    if (!std::isfinite(v)) fail("a finite number");
    return v;
  }
  int integer() const {
    if (!j_.is_number_integer()) fail("an integer");
    const auto v = j_.get<std::int64_t>();
    if (v < -(1 << 28) || v > (1 << 28)) fail("an integer of at most 2^28 in size");
    return int(v);
  }
  bool boolean() const {
    if (!j_.is_boolean()) fail("true or false");
    return j_.get<bool>();
  }
  geometry::Index3 index3() const {
    if (size() != 3) fail("[i, j, k]");
    return {at(0).integer(), at(1).integer(), at(2).integer()};
  }
  geometry::Vec3 vec3() const {
    if (size() != 3) fail("[x, y, z]");
    return {at(0).number(), at(1).number(), at(2).number()};
  }

 private:
  const json& j_;
  std::string file_, pointer_;
};

// A region as a plan's .vdb gives it (storage around its voxels) on the plan's lattice,
// clipped to the domain.
geometry::Solid on_plan_grid(const geometry::Solid& s, const geometry::Lattice& lattice, const geometry::IndexBox& domain) {
  if (s.lattice() == lattice) return intersect(s, geometry::Solid::filled(lattice, domain));
  geometry::Solid out = copied_onto(s, lattice, domain);  // the same grid up to rounding of the origin
  return out;
}

// A .vdb of the plan on the plan's lattice, clipped to the domain.
geometry::Solid load_region(const fs::path& directory, const Node& file_node, const geometry::Lattice& lattice,
                            const geometry::IndexBox& domain) {
  const std::string relative = file_node.str();
  if (relative.empty() || fs::path(relative).is_absolute() || relative.find("..") != std::string::npos)
    file_node.fail("a relative path inside the plan directory");
  const fs::path path = directory / relative;
  const geometry::Solid s = geometry::read_vdb(path);
  const double h = lattice.voxel_size;
  const auto& o = s.lattice().origin;
  if (!s.empty() && (std::abs(s.voxel_size() - h) > 1e-9 * h || std::abs(o.x - lattice.origin.x) > 1e-6 * h ||
                     std::abs(o.y - lattice.origin.y) > 1e-6 * h || std::abs(o.z - lattice.origin.z) > 1e-6 * h))
    throw InputError(path.string() + ": voxel size " + std::to_string(s.voxel_size()) + " mm; expected the plan's grid (" +
                     std::to_string(h) + " mm)");
  return on_plan_grid(s, lattice, domain);
}

// The machine: embedded (`yaml` and its `hash`) since plans carry it; older plans name
// only its `file`.
void read_machine(const Node& machine, PlanFile& f) {
  f.machine_file = machine.at("file").str();
  if (!machine.has("yaml")) return;
  f.machine_yaml = machine.at("yaml").str();
  f.machine_hash = machine.at("hash").str();
  if (f.machine_hash != machine_text_hash(f.machine_yaml))
    machine.at("hash").fail("\"" + machine_text_hash(f.machine_yaml) + "\", the FNV-1a 64 hash of /machine/yaml");
}

fs::path plan_json_path(const fs::path& given) { return fs::is_directory(given) ? given / "plan.json" : given; }

std::string read_plan_text(const fs::path& json_path) {
  std::ifstream in(json_path, std::ios::binary);
  if (!in) throw InputError(json_path.string() + ": cannot read: no such file (expected a plan.json written by `hybridctl plan`)");
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

json parse_plan_json(std::string_view json_text, const std::string& name) {
  json root;
  try {
    root = json::parse(json_text);
  } catch (const json::exception& e) {
    // A syntax error (parse_error, with the place) or a number beyond a double's range
    // (out_of_range 406, naming the number).
    throw InputError(name + ": not JSON: " + e.what());
  }
  const Node top(root, name, "");
  if (top.at("format").str() != "hybridctl-plan") top.at("format").fail("\"hybridctl-plan\"");
  if (top.at("version").integer() != 1) top.at("version").fail("version 1 (this hybridctl reads version 1)");
  return root;
}

void read_grid(const Node& grid, geometry::Lattice& lattice, geometry::IndexBox& domain) {
  lattice.voxel_size = grid.at("voxel_size").number();
  if (lattice.voxel_size <= 0) grid.at("voxel_size").fail("a positive voxel size");
  lattice.origin = grid.at("origin").vec3();
  domain = {grid.at("domain").at("lo").index3(), grid.at("domain").at("hi").index3()};
  if (domain.empty()) grid.at("domain").fail("a non-empty box");
  if (double(domain.voxel_count()) > 4e9) grid.at("domain").fail("a domain of at most 4e9 voxels");
}

}  // namespace

PlanFile read_plan_file(const fs::path& given) {
  const fs::path json_path = plan_json_path(given);
  return parse_plan_file(read_plan_text(json_path), json_path);
}

PlanGrid read_plan_grid(const fs::path& given) {
  const fs::path json_path = plan_json_path(given);
  const json root = parse_plan_json(read_plan_text(json_path), json_path.string());
  const Node top(root, json_path.string(), "");
  PlanGrid g;
  read_grid(top.at("grid"), g.lattice, g.domain);
  g.primitives = top.at("primitives").size();
  return g;
}

namespace {

// The primitive a plan's step names, as an index.
int primitive_index(const Node& name, const PlanFile& f) {
  const std::string prim = name.str();
  for (std::size_t i = 0; i < f.primitives.size(); ++i)
    if (f.primitives[i].name == prim) return int(i);
  name.fail("the name of one of the plan's primitives");
}

RejectionReason read_reason(const Node& n) {
  RejectionReason r;
  r.kind = n.at("kind").str();
  if (n.has("action")) r.action = n.at("action").integer();
  if (n.has("line")) r.line = n.at("line").integer();
  if (n.has("message")) r.message = n.at("message").str();
  if (n.has("where")) r.where = n.at("where").vec3();
  return r;
}

// plan.json's `rejected`: candidates validation turned down (docs/plan-format.md).
void read_rejected(const Node& rejected, PlanFile& f) {
  for (std::size_t k = 0; k < rejected.size(); ++k) {
    const Node p = rejected.at(k);
    PlanFileRejected out;
    out.expression = p.at("expression").str();
    out.cost = p.at("cost").number();
    const Node steps = p.at("steps");
    for (std::size_t s = 0; s < steps.size(); ++s) {
      const Node a = steps.at(s);
      PlanFileAction action;
      action.primitive = primitive_index(a.at("primitive"), f);
      if (a.has("volume")) action.volume = a.at("volume").number();
      if (a.has("cost")) action.cost = a.at("cost").number();
      out.actions.push_back(action);
    }
    const Node reasons = p.at("reasons");
    for (std::size_t i = 0; i < reasons.size(); ++i) out.reasons.push_back(read_reason(reasons.at(i)));
    f.rejected.push_back(std::move(out));
  }
}

// The copy the plan directory holds, wherever it was copied to; else the part it names;
// else none (a design made on voxels). One that is there but unreadable is an error.
geometry::TriangleMesh design_mesh_of(const PlanFile& f) {
  std::error_code ec;
  const fs::path copy = f.directory / kDesignStl;
  if (fs::is_regular_file(copy, ec)) return geometry::read_stl(copy);
  if (f.part.empty()) return {};
  fs::path part(f.part);
  if (part.is_relative()) part = f.directory / part;
  if (fs::is_regular_file(part, ec)) return geometry::read_stl(part);
  return {};
}

}  // namespace

PlanFile parse_plan_file(std::string_view json_text, const fs::path& json_path) {
  const std::string name = json_path.string();
  const json root = parse_plan_json(json_text, name);
  const Node top(root, name, "");
  PlanFile f;
  f.directory = json_path.parent_path().empty() ? fs::path(".") : json_path.parent_path();
  f.part = top.at("part").str();
  f.machine_name = top.at("machine").at("name").str();
  read_machine(top.at("machine"), f);
  read_grid(top.at("grid"), f.lattice, f.domain);
  f.tolerance = top.at("tolerance").number();
  f.design = load_region(f.directory, top.at("design").at("file"), f.lattice, f.domain);
  f.design_mesh = design_mesh_of(f);

  const Node prims = top.at("primitives");
  for (std::size_t i = 0; i < prims.size(); ++i) {
    const Node p = prims.at(i);
    PlanFilePrimitive q;
    q.name = p.at("name").str();
    q.label = p.at("label").str();
    const std::optional<PrimitiveKind> kind = config::primitive_kind_named(p.at("kind").str());
    if (!kind) p.at("kind").fail("one of \"raw-stock\", \"u-am\", \"o-am\", \"sm-max\", \"sm-cons\", \"file\"");
    q.kind = *kind;
    const std::string mode = p.at("mode").str();
    if (mode != "additive" && mode != "subtractive") p.at("mode").fail("\"additive\" or \"subtractive\"");
    q.mode = mode == "additive" ? Mode::Additive : Mode::Subtractive;
    q.capability = p.at("capability").str();
    q.setup = p.at("setup").str();
    if (p.has("tool_number")) q.tool_number = p.at("tool_number").integer();
    q.region = load_region(f.directory, p.at("file"), f.lattice, f.domain);
    f.primitives.push_back(std::move(q));
  }
  const Node plans = top.at("plans");
  for (std::size_t k = 0; k < plans.size(); ++k) {
    const Node p = plans.at(k);
    PlanFilePlan plan;
    plan.rank = p.at("rank").integer();
    plan.expression = p.at("expression").str();
    plan.cost = p.at("cost").number();
    const Node actions = p.at("actions");
    for (std::size_t s = 0; s < actions.size(); ++s) {
      const Node a = actions.at(s);
      const std::string prim = a.at("primitive").str();
      PlanFileAction action;
      for (std::size_t i = 0; i < f.primitives.size(); ++i)
        if (f.primitives[i].name == prim) action.primitive = int(i);
      if (action.primitive < 0) a.at("primitive").fail("the name of one of the plan's primitives");
      action.volume = a.at("volume").number();
      action.cost = a.at("cost").number();
      plan.actions.push_back(action);
    }
    f.plans.push_back(std::move(plan));
  }
  if (top.has("rejected")) read_rejected(top.at("rejected"), f);
  return f;
}

geometry::Solid as_read_back(const geometry::Solid& s, const geometry::Lattice& lattice, const geometry::IndexBox& domain) {
  return on_plan_grid(intersect(s, geometry::Solid::filled(s.lattice(), s.bounding_box())), lattice, domain);
}

std::string path_from_plan_directory(const std::string& path, const std::filesystem::path& directory) {
  if (path.empty()) return path;
  const fs::path absolute = fs::absolute(path).lexically_normal();
  const fs::path relative = absolute.lexically_relative(fs::absolute(directory).lexically_normal());
  return relative.empty() ? absolute.generic_string() : relative.generic_string();
}

std::vector<geometry::Solid> plan_states(const PlanFile& file, const PlanFilePlan& plan) {
  std::vector<geometry::Solid> states;
  states.emplace_back(file.lattice, file.domain);
  for (const PlanFileAction& a : plan.actions) {
    const PlanFilePrimitive& p = file.primitives[std::size_t(a.primitive)];
    states.push_back(p.mode == Mode::Additive ? unite(states.back(), p.region) : subtract(states.back(), p.region));
  }
  return states;
}

}  // namespace hybridctl::plan
