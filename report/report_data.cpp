#include "report/report_data.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <unordered_map>

#include <tbb/parallel_for.h>
#include <tbb/task_group.h>

#include "common/error.hpp"
#include "common/hash.hpp"
#include "plan/plan_machine.hpp"
#include "report/report_as_built.hpp"
#include "report/report_atoms.hpp"

namespace hybridctl::report {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

fs::path plan_json_path(const fs::path& plan) { return fs::is_directory(plan) ? plan / "plan.json" : plan; }

json read_json(const fs::path& path, const char* what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string() + ": cannot read " + what);
  std::stringstream text;
  text << in.rdbuf();
  try {
    return json::parse(text.str());
  } catch (const json::parse_error& e) {
    throw InputError(path.string() + ": not JSON (" + e.what() + "); expected " + what);
  }
}

// A member of a plan.json object, or `fallback` when absent (fields added by later
// versions of the planner are shown when there and never required).
json field(const json& object, const char* key, json fallback = nullptr) {
  return object.is_object() && object.contains(key) ? object.at(key) : fallback;
}

// FNV-1a 64 over the solid's lattice and occupied words: equal solids hash equally.
std::uint64_t solid_hash(const geometry::Solid& solid) {
  Fnv1a64 h;
  const auto mix = [&h](std::uint64_t v) { h.update_word(v); };
  const geometry::IndexBox box = solid.bounding_box();
  mix(std::uint64_t(solid.voxel_count()));
  if (box.empty()) return h.value();
  for (int z = box.lo.z; z < box.hi.z; ++z)
    for (int y = box.lo.y; y < box.hi.y; ++y)
      for (int w = solid.first_word(); w < solid.first_word() + solid.words_per_row(); ++w)
        if (const std::uint64_t word = solid.word_at(w, y, z)) mix(word ^ (std::uint64_t(w) << 48) ^ (std::uint64_t(y) << 24) ^ std::uint64_t(z));
  return h.value();
}

json toolpath_json(const ActionPath& path) {
  json out = {{"step", path.step}, {"makes_gcode", path.makes_gcode}, {"note", path.note}};
  if (!path.makes_gcode) return out;
  out["additive"] = path.additive;
  out["instrument"] = path.instrument;
  out["tool_number"] = path.tool_number;
  out["setup"] = path.setup;
  out["segments"] = path.segments();
  out["p"] = base64(path.points.data(), path.points.size() * sizeof(float));
  out["k"] = base64(path.kinds.data(), path.kinds.size());
  out["l"] = base64(path.layers.data(), path.layers.size() * sizeof(std::uint16_t));
  out["layer_z"] = path.layer_z;
  out["cycle_s"] = path.cycle_s;
  out["lengths"] = {{"process", path.process_length}, {"feed", path.feed_length}, {"rapid", path.rapid_length}};
  out["warnings"] = path.warnings;
  return out;
}

class Gatherer {
 public:
  Gatherer(const ReportRequest& request, ReportData& data)
      : request_(request), data_(data), raw_(read_json(plan_json_path(request.plan), "a plan.json (hybridctl plan -o DIR)")),
        owned_(request.in_memory ? plan::PlanFile{} : plan::read_plan_file(request.plan)),
        file_(request.in_memory ? *request.in_memory : owned_), machine_(plan::plan_machine(file_, {}).machine) {}

  void run() {
    json& doc = data_.document;
    doc["format"] = "hybridctl-report";
    doc["version"] = 1;
    for (const char* key : {"part", "tolerance", "sliver_threshold", "cost_normaliser", "fixed_costs", "search",
                            "learned", "timings_s", "grid"})
      doc[key] = field(raw_, key);
    doc["machine"] = {{"name", file_.machine_name}, {"file", file_.machine_file}};
    doc["voxel_size"] = file_.lattice.voxel_size;
    doc["domain_mm"] = box_json(file_.lattice.extent(file_.domain));
    doc["budget"] = budget_json();
    data_.tolerance = file_.tolerance;
    design();
    primitives();
    atoms_and_verdict();
    plans_and_exact();
    doc["rejected"] = field(raw_, "rejected", json::array());
    if (!request_.as_built.empty()) as_built_section();
    mesh_all();
  }

 private:
  static json vec(const geometry::Vec3& v) { return json::array({v.x, v.y, v.z}); }
  static json box_json(const geometry::Box3& b) { return {{"min", vec(b.min)}, {"max", vec(b.max)}}; }

  json budget_json() const {
    const MeshBudget& b = request_.budget;
    return {{"design", b.design},   {"primitive", b.primitive}, {"atom_class", b.atom_class},
            {"violating_atom", b.violating_atom}, {"state", b.state}, {"as_built", b.as_built},
            {"design_stl", b.design_stl}, {"page_bytes", request_.size_budget}};
  }

  // A placeholder for a solid's mesh, filled in by mesh_all(). Plans share states (the
  // design, the raw stock, the same deposit), so each distinct solid is meshed once per budget.
  json mesh(const geometry::Solid& solid, std::size_t budget) {
    const std::uint64_t key = solid_hash(solid) ^ (std::uint64_t(budget) * 0x9E3779B97F4A7C15ull);
    for (auto [it, end] = job_index_.equal_range(key); it != end; ++it)
      if (jobs_[it->second].budget == budget && jobs_[it->second].solid == solid) return {{"mesh_job", it->second}};
    jobs_.push_back({solid, budget});
    job_index_.emplace(key, jobs_.size() - 1);
    return {{"mesh_job", jobs_.size() - 1}};
  }
  static std::size_t job_of(const json& placeholder) { return placeholder.at("mesh_job").get<std::size_t>(); }

  // Meshes every distinct solid, in parallel, and puts the meshes where they were asked for.
  void mesh_all() {
    std::vector<IndexedMesh> meshes(jobs_.size());
    tbb::parallel_for(std::size_t(0), jobs_.size(), [&](std::size_t i) { meshes[i] = budget_mesh(jobs_[i].solid, jobs_[i].budget); });
    fill(data_.document, meshes);
    data_.design = meshes[design_job_];
    for (std::size_t i = 0; i < violating_jobs_.size(); ++i) data_.violating.push_back(meshes[violating_jobs_[i]]);
    for (std::size_t k = 0; k < state_jobs_.size(); ++k)
      for (const std::size_t job : state_jobs_[k]) data_.plans[k].states.push_back(meshes[job]);
  }
  void fill(json& j, const std::vector<IndexedMesh>& meshes) {
    if (j.is_object() && j.contains("mesh_job")) {
      const IndexedMesh& m = meshes[job_of(j)];
      data_.triangles += m.triangles();
      j = mesh_json(m);
      return;
    }
    if (j.is_structured())
      for (json& child : j) fill(child, meshes);
  }

  void design() {
    json d = field(raw_, "design", json::object());
    d["mesh"] = mesh(file_.design, request_.budget.design);
    design_job_ = job_of(d["mesh"]);
    data_.document["design"] = d;
  }

  void primitives() {
    json out = json::array();
    const json listed = field(raw_, "primitives", json::array());
    for (std::size_t p = 0; p < file_.primitives.size(); ++p) {
      json entry = p < listed.size() ? listed[p] : json::object();
      entry["name"] = file_.primitives[p].name;
      entry["mesh"] = mesh(file_.primitives[p].region, request_.budget.primitive);
      out.push_back(std::move(entry));
    }
    data_.document["primitives"] = out;
  }

  void atoms_and_verdict() {
    const json atoms = field(raw_, "atoms", json::array());
    std::vector<std::string> codes, classes;
    json counts = json::object();
    for (const json& a : atoms) {
      codes.push_back(field(a, "code", "").get<std::string>());
      classes.push_back(field(a, "class", "").get<std::string>());
      json& c = counts[classes.back()];
      c["atoms"] = field(c, "atoms", 0).get<int>() + 1;
      c["volume"] = field(c, "volume", 0.0).get<double>() + field(a, "volume", 0.0).get<double>();
    }
    json verdict = field(raw_, "verdict", json::object());
    json violations = field(verdict, "violations", json::array());
    std::vector<int> ids;
    for (const json& v : violations) ids.push_back(field(v, "atom", -1).get<int>());
    const AtomSolids solids = atom_solids(file_, codes, classes, ids);
    for (std::size_t i = 0; i < violations.size(); ++i) {
      violations[i]["mesh"] = mesh(solids.violating[i], request_.budget.violating_atom);
      violating_jobs_.push_back(job_of(violations[i]["mesh"]));
    }
    verdict["violations"] = violations;
    const std::pair<const char*, const geometry::Solid*> by_class[] = {
        {"must-in", &solids.must_in}, {"must-out", &solids.must_out}, {"free", &solids.free}};
    for (const auto& [name, solid] : by_class) counts[name]["mesh"] = mesh(*solid, request_.budget.atom_class);
    data_.document["atoms"] = {{"count", atoms.size()}, {"classes", counts}};
    data_.document["verdict"] = verdict;
  }

  json action_entry(const json& raw_action, const plan::PlanFileAction& action) const {
    json entry = raw_action.is_object() ? raw_action : json::object();
    entry.erase("region_atoms");
    const plan::PlanFilePrimitive& p = file_.primitives.at(std::size_t(action.primitive));
    entry["primitive"] = p.name;
    entry["label"] = p.label;
    entry["kind"] = p.kind;
    entry["mode"] = p.mode == config::Mode::Additive ? "additive" : "subtractive";
    entry["capability"] = p.capability;
    entry["setup"] = p.setup;
    entry["tool_number"] = p.tool_number;
    if (!entry.contains("volume")) entry["volume"] = action.volume;
    if (!entry.contains("cost")) entry["cost"] = action.cost;
    return entry;
  }

  // What each plan needs that takes time: its states, then the toolpaths of all plans
  // (each distinct action once) or why a plan has none.
  struct PlanWork {
    std::vector<geometry::Solid> states;
    PlanPaths paths;
  };
  std::vector<PlanWork> plan_work() const {
    std::vector<std::vector<geometry::Solid>> states(file_.plans.size());
    tbb::parallel_for(std::size_t(0), states.size(), [&](std::size_t k) { states[k] = plan::plan_states(file_, file_.plans[k]); });
    std::vector<PlanPaths> paths = plan_paths(file_, states, machine_);
    std::vector<PlanWork> work(file_.plans.size());
    for (std::size_t k = 0; k < work.size(); ++k) work[k] = {std::move(states[k]), std::move(paths[k])};
    return work;
  }

  void plans() {
    json out = json::array();
    const json listed = field(raw_, "plans", json::array());
    std::vector<PlanWork> work = plan_work();
    for (std::size_t k = 0; k < file_.plans.size(); ++k) {
      const plan::PlanFilePlan& plan = file_.plans[k];
      json entry = k < listed.size() ? listed[k] : json::object();
      entry.erase("final_atoms");
      if (!work[k].paths.error.empty()) entry["toolpath_error"] = work[k].paths.error;
      const json raw_actions = field(entry, "actions", json::array());
      const PlanPaths& paths = work[k].paths;
      if (k == 0) line_positions_ = paths.line_positions;
      json actions = json::array();
      state_jobs_.emplace_back();
      double cycle = 0;
      for (std::size_t a = 0; a < plan.actions.size(); ++a) {
        json action = action_entry(a < raw_actions.size() ? raw_actions[a] : json(), plan.actions[a]);
        action["state"] = mesh(work[k].states.at(a + 1), request_.budget.state);
        state_jobs_.back().push_back(job_of(action["state"]));
        if (a < paths.actions.size()) {
          action["toolpath"] = toolpath_json(paths.actions[a]);
          cycle += paths.actions[a].cycle_s;
          data_.segments += paths.actions[a].segments();
        }
        actions.push_back(std::move(action));
        ++data_.actions;
      }
      entry["actions"] = actions;
      // The plan's program's cycle time, changes included, as `plan` measured it; else its
      // actions' motion.
      const json cycle_time = field(entry, "cycle_time", json());
      entry["cycle_s"] = cycle_time.is_object() && cycle_time.contains("seconds") ? cycle_time["seconds"] : json(cycle);
      data_.plans.push_back(PlanView{{}, paths.actions, std::nullopt});
      out.push_back(std::move(entry));
    }
    data_.document["plans"] = out;
  }

  // The plans' states and toolpaths, and beside them, in another task (on the bundled
  // parts they take about as long), each plan's exact deviation on the design's mesh.
  void plans_and_exact() {
    std::optional<ExactMaps> exact;
    std::string error;
    tbb::task_group side;
    const bool measure = request_.exact_plans > 0 && !file_.plans.empty();
    if (measure)
      side.run([&] {
        try {
          exact = exact_maps(file_, machine_, request_.exact_plans, request_.budget.design_stl);
        } catch (const std::exception& e) {
          error = e.what();
        }
      });
    try {
      plans();
    } catch (...) {
      side.wait();
      throw;
    }
    side.wait();
    if (measure) exact_section(exact, error);
  }

  void exact_section(const std::optional<ExactMaps>& exact, const std::string& error);
  void as_built_section();

  const ReportRequest& request_;
  ReportData& data_;
  json raw_;
  plan::PlanFile owned_;  // read from the directory when the request holds none
  const plan::PlanFile& file_;
  config::Machine machine_;
  std::vector<geometry::Vec3> line_positions_;
  struct MeshJob {
    geometry::Solid solid;
    std::size_t budget;
  };
  std::vector<MeshJob> jobs_;
  std::unordered_multimap<std::uint64_t, std::size_t> job_index_;  // by solid_hash and budget
  std::size_t design_job_ = 0;
  std::vector<std::size_t> violating_jobs_;
  std::vector<std::vector<std::size_t>> state_jobs_;  // per plan, per action
};

json exact_place_json(const plan::ExactPlace& p) {
  return {{"mm", p.mm},
          {"at", p.at ? json::array({p.at->x, p.at->y, p.at->z}) : json(nullptr)},
          {"action", p.action},
          {"line", p.line},
          {"as_deposited", p.as_deposited},
          {"at_least", p.at_least}};
}

// The shape of plan.json's deviation.exact (docs/plan-format.md).
json exact_summary_json(const plan::ExactDeviation& e) {
  return {{"max_excess_mm", e.excess.mm},   {"max_gouge_mm", e.gouge.mm},
          {"excess", exact_place_json(e.excess)}, {"gouge", exact_place_json(e.gouge)},
          {"within_share", e.within_share}, {"within_tolerance", e.within_tolerance()},
          {"tolerance", e.tolerance},       {"spacing", e.spacing},
          {"samples", e.samples}};
}

// One plan's figures per triangle of design.surface (docs/report.md, "Data").
json exact_map_json(const TriangleDeviations& d) {
  if (!d.error.empty()) return {{"error", d.error}};
  const double tolerance = d.summary.tolerance;
  std::size_t beyond = 0, deposited = 0;
  for (std::size_t t = 0; t < d.excess.size(); ++t) {
    if (d.excess[t] > tolerance || d.gouge[t] > tolerance) ++beyond;
    deposited += d.deposited[t];
  }
  return {{"summary", exact_summary_json(d.summary)},
          {"triangles", d.excess.size()},
          {"beyond_triangles", beyond},
          {"deposited_triangles", deposited},
          {"excess", base64(d.excess.data(), d.excess.size() * sizeof(float))},
          {"gouge", base64(d.gouge.data(), d.gouge.size() * sizeof(float))},
          {"action", base64(d.action.data(), d.action.size() * sizeof(std::uint16_t))},
          {"deposited", base64(d.deposited.data(), d.deposited.size())}};
}

void Gatherer::exact_section(const std::optional<ExactMaps>& exact, const std::string& error) {
  json& surface = data_.document["design"]["surface"];
  if (!error.empty()) {
    surface = {{"error", error}};
    return;
  }
  if (!exact) {
    surface = {{"error", "no STL: the design was given as voxels, so there is no real surface to measure the plans against"}};
    return;
  }
  const std::size_t triangles = exact->design.triangles();
  surface = {{"file", exact->stl}, {"triangles", triangles}};
  if (triangles > request_.budget.design_stl) {
    surface["error"] = "the STL has " + std::to_string(triangles) + " triangles, over the report's budget of " +
                       std::to_string(request_.budget.design_stl) + " for it: no exact deviation map";
    return;
  }
  surface["mesh"] = mesh_json(exact->design);
  data_.triangles += triangles;
  data_.design_stl = exact->design;
  json& plans = data_.document["plans"];
  for (std::size_t k = 0; k < exact->plans.size() && k < plans.size(); ++k) {
    plans[k]["exact_map"] = exact_map_json(exact->plans[k]);
    if (exact->plans[k].error.empty()) data_.plans[k].exact = exact->plans[k];
  }
}

void Gatherer::as_built_section() {
  const AsBuilt built = as_built(file_, request_.as_built);
  const std::size_t budget = request_.budget.as_built;
  json section = {{"built", mesh(built.built, budget)},
                  {"built_volume", built.built.volume()},
                  {"bands",
                   {{"over_within", {{"volume", built.over_within.volume()}, {"mesh", mesh(built.over_within, budget)}}},
                    {"over_beyond", {{"volume", built.over_beyond.volume()}, {"mesh", mesh(built.over_beyond, budget)}}},
                    {"under_within", {{"volume", built.under_within.volume()}, {"mesh", mesh(built.under_within, budget)}}},
                    {"under_beyond",
                     {{"volume", built.under_beyond.volume()}, {"mesh", mesh(built.under_beyond, budget)}}}}}};
  json alarms = json::array();
  if (!request_.run_report.empty()) {
    const json run = read_json(request_.run_report, "a run report (hybridctl sim serve --report)");
    section["run"] = {{"ended_by", field(run, "ended_by")},      {"lines_executed", field(run, "lines_executed")},
                      {"virtual_time_s", field(run, "virtual_time_s")}, {"alarms", field(run, "alarms")},
                      {"volumes_mm3", field(run, "volumes_mm3")}, {"final_status", field(run, "final_status")}};
    const json status = field(run, "final_status", json::object());
    const std::string alarm = field(status, "alarm", "NONE").get<std::string>();
    const long line = field(status, "alarm_line", 0).get<long>();
    if (alarm != "NONE" && !alarm.empty()) {
      json entry = {{"alarm", alarm}, {"line", line}};
      if (line >= 1 && std::size_t(line) <= line_positions_.size()) entry["where"] = vec(line_positions_[line - 1]);
      alarms.push_back(entry);
    }
  }
  section["alarms"] = alarms;
  data_.document["as_built"] = section;
}

}  // namespace

json mesh_json(const IndexedMesh& mesh) {
  json out = {{"triangles", mesh.triangles()}, {"voxel", mesh.voxel_size}};
  if (mesh.empty()) return out;
  float lo[3] = {mesh.positions[0], mesh.positions[1], mesh.positions[2]}, hi[3] = {lo[0], lo[1], lo[2]};
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    lo[i % 3] = std::min(lo[i % 3], mesh.positions[i]);
    hi[i % 3] = std::max(hi[i % 3], mesh.positions[i]);
  }
  // Positions as 16-bit steps across the mesh's box: a few micrometres for a 300 mm part.
  std::vector<std::uint16_t> q(mesh.positions.size());
  for (std::size_t i = 0; i < q.size(); ++i) {
    const float span = hi[i % 3] - lo[i % 3];
    q[i] = span > 0 ? std::uint16_t(std::lround((mesh.positions[i] - lo[i % 3]) / span * 65535.0f)) : 0;
  }
  out["lo"] = {lo[0], lo[1], lo[2]};
  out["hi"] = {hi[0], hi[1], hi[2]};
  out["p"] = base64(q.data(), q.size() * sizeof(std::uint16_t));
  const std::size_t vertices = mesh.positions.size() / 3;
  if (vertices <= 65536) {
    std::vector<std::uint16_t> i16(mesh.indices.begin(), mesh.indices.end());
    out["i16"] = base64(i16.data(), i16.size() * sizeof(std::uint16_t));
  } else {
    out["i32"] = base64(mesh.indices.data(), mesh.indices.size() * sizeof(std::uint32_t));
  }
  return out;
}

ReportData report_data(const ReportRequest& request) {
  ReportData data;
  Gatherer(request, data).run();
  return data;
}

}  // namespace hybridctl::report
