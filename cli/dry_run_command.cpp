// hybridctl dry-run: plan a part (every plan offered proven by execution), run the best
// plan, plan N or every plan through a simulated controller of its own (a separate
// `hybridctl sim serve` process on loopback, over Modbus TCP or socketcand) from the raw
// stock, and compare what it built with what was planned and with the design.

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <thread>

#include "cli/commands.hpp"
#include "cli/memory_budget.hpp"
#include "cli/objective.hpp"
#include "cli/ranges.hpp"
#include "cli/report_job.hpp"
#include "cli/run_job.hpp"
#include "common/error.hpp"
#include "config/machine_loader.hpp"
#include "config/transport_uri.hpp"
#include "geometry/mesh.hpp"
#include "geometry/vdb_file.hpp"
#include "gcode/program.hpp"
#include "plan/plan_file.hpp"
#include "plan/deviation.hpp"
#include "plan/start_stock.hpp"
#include "planner/pipeline/candidate_execution.hpp"
#include "planner/pipeline/plan_report.hpp"
#include "validation/plan_validator.hpp"
#include "verification/exact_deviation.hpp"
#include "gcode/post.hpp"

namespace hybridctl::cli {
namespace {

namespace fs = std::filesystem;

struct DryRunArgs {
  std::string part, machine, output = "out/dry-run", transport = "modbus";
  int plan = 1;
  bool all = false;
  double voxel = 0, tolerance = -1;
  int reuse = 1;
  std::string memory_budget;
  std::vector<std::string> stock_files;
  std::string objective;
  double time_scale = 0;
  bool report = false;
  bool verbose = false;
};

// `hybridctl sim serve` as a child process; killed when this goes out of scope.
class Simulator {
 public:
  Simulator(const std::vector<std::string>& args, const fs::path& log) {
    int out[2];
    if (::pipe(out) != 0) throw std::runtime_error("pipe failed");
    pid_ = ::fork();
    if (pid_ < 0) throw std::runtime_error("fork failed");
    if (pid_ == 0) {
      ::dup2(out[1], STDOUT_FILENO);
      const int err = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      if (err >= 0) ::dup2(err, STDERR_FILENO);
      ::close(out[0]);
      std::vector<char*> argv;
      for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
      argv.push_back(nullptr);
      ::execv("/proc/self/exe", argv.data());
      ::_exit(127);
    }
    ::close(out[1]);
    stdout_ = ::fdopen(out[0], "r");
  }
  ~Simulator() {
    if (pid_ > 0 && !exited_) {
      ::kill(pid_, SIGTERM);
      wait();
    }
    if (stdout_) std::fclose(stdout_);
  }
  // The port from the first line starting with `listening KIND`.
  int port(const std::string& kind) {
    char line[512];
    while (std::fgets(line, sizeof line, stdout_)) {
      const std::string l(line);
      const std::string key = "listening " + kind + " ";
      if (l.rfind(key, 0) != 0) continue;
      const std::string address = l.substr(key.size(), l.find_last_not_of("\r\n") + 1 - key.size());
      const config::HostPortResult at = config::parse_listen_address(address);
      if (!at.host_port) throw std::runtime_error("the simulator printed '" + l + "': " + at.error);
      return at.host_port->port;
    }
    throw std::runtime_error("the simulator did not start (see its log)");
  }
  int wait() {
    int status = 0;
    ::waitpid(pid_, &status, 0);
    exited_ = true;
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  }
  // How it ended, when it has: "exited with 3", "killed by signal 6"; empty while it runs.
  std::string ended() {
    int status = 0;
    if (exited_ || ::waitpid(pid_, &status, WNOHANG) != pid_) return exited_ ? "exited" : "";
    exited_ = true;
    return WIFEXITED(status) ? "exited with " + std::to_string(WEXITSTATUS(status))
                             : "killed by signal " + std::to_string(WTERMSIG(status));
  }

 private:
  pid_t pid_ = -1;
  bool exited_ = false;
  FILE* stdout_ = nullptr;
};

// The last `lines` lines of a text file, each indented; empty when it cannot be read.
std::string log_tail(const fs::path& file, std::size_t lines) {
  std::ifstream in(file);
  std::deque<std::string> last;
  for (std::string line; std::getline(in, line);) {
    last.push_back("  | " + line + "\n");
    if (last.size() > lines) last.pop_front();
  }
  std::string out;
  for (const std::string& l : last) out += l;
  return out;
}

// One offered plan run through a fresh simulated controller from the plan's raw stock, in
// OUT/plan-N; prints as built against as planned and against the design, both ways, and
// every alarm with its line. Returns true when it ran to the end with no alarm and within
// the tolerance.
bool dry_run_plan(const DryRunArgs& a, const config::Machine& machine, verification::DesignSurfaces& surfaces,
                  const plan::PlanFile& file, int rank, const fs::path& out) {
  const fs::path plan_json = file.directory / "plan.json";
  const plan::PlanFilePlan& plan = file.plans[std::size_t(rank - 1)];
  std::printf("plan %-6d %s  cost %.4f\n", rank, plan.expression.c_str(), plan.cost);
  fs::create_directories(out);
  // 1. A simulated controller on loopback, starting from the plan's raw stock.
  const fs::path report = out / "sim-report.json", as_built = out / "as-built.vdb", lines_log = out / "executed-lines.ngc";
  std::vector<std::string> args = {"hybridctl", "sim", "serve", "--machine", a.machine, "--stock", plan_json.string(),
                                   "--plan", std::to_string(rank), "--time-scale", std::to_string(a.time_scale),
                                   "--exit-when-done", "--report", report.string(), "--as-built", as_built.string(),
                                   "--line-log", lines_log.string()};
  if (a.transport == "modbus") {
    args.insert(args.end(), {"--modbus", "tcp://127.0.0.1:0"});
  } else {
    args.insert(args.end(), {"--socketcand", "127.0.0.1:0"});
  }
  Simulator sim(args, out / "sim.log");
  const int port = sim.port(a.transport == "modbus" ? "modbus-tcp" : "socketcand");
  const std::string uri = a.transport == "modbus" ? "modbus-tcp://127.0.0.1:" + std::to_string(port)
                                                  : "socketcand://127.0.0.1:" + std::to_string(port) + "/can0";
  std::printf("simulator   %s (log %s)\n", uri.c_str(), (out / "sim.log").c_str());

  // 2. The plan through it, unattended.
  fs::remove_all(out / "job");
  RunRequest run;
  run.input = plan_json.string();
  run.transport = uri;
  run.rank = rank;
  run.job = (out / "job").string();
  run.yes = true;
  std::vector<std::pair<std::string, std::uint32_t>> alarms;
  const int code = run_job(run, &alarms);
  const int sim_code = code == kSuccess ? sim.wait() : 0;
  if (code == kSuccess && sim_code != 0) throw std::runtime_error("the simulator exited with " + std::to_string(sim_code));
  for (const auto& [name, line] : alarms) std::printf("alarm       %s at line %u\n", name.c_str(), unsigned(line));
  if (code != kSuccess) {
    std::printf("result      plan %d STOPPED before its end (exit %d)\n", rank, code);
    // Why the controller went away, if it did: its own last words (a crash, a sanitizer's
    // report) would otherwise be lost with the directory.
    if (const std::string ended = sim.ended(); !ended.empty()) {
      std::printf("simulator   %s; the end of %s:\n", ended.c_str(), (out / "sim.log").c_str());
      std::fputs(log_tail(out / "sim.log", 20).c_str(), stdout);
    }
    return false;
  }

  // 3. As built versus as planned and versus the design.
  const geometry::Solid planned_shape = plan::plan_states(file, plan).back();
  const geometry::Solid built = geometry::read_vdb(as_built);
  const geometry::Solid built_here = copied_onto(built, file.lattice, file.domain);
  const geometry::Solid extra = subtract(built_here, planned_shape), missing = subtract(planned_shape, built_here);
  const plan::Deviation d = plan::measure_deviation(built_here, file.design, file.domain, file.band());
  std::printf("as built    %.1f mm³ (planned %.1f mm³): %.1f mm³ beyond the plan, %.1f mm³ of it missing\n",
              built_here.volume(), planned_shape.volume(), extra.volume(), missing.volume());
  std::printf("on voxels   %s\n", plan::deviation_text(d, file.band()).c_str());
  // 4. The program the controller ran, against the design's real surface: the voxels
  // judge within their band only, the drawing's tolerance is judged here
  // (docs/verification.md).
  bool exact_within = true;
  if (const verification::DesignSurface* surface = surfaces.for_plan(file)) {
    std::ifstream in(out / "job" / "program.ngc", std::ios::binary);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const plan::ExactDeviation exact =
        verification::verify_program(*surface, machine, gcode::PostedProgram::from_text(text),
                                     plan::start_stock(file, plan, machine), {file.tolerance});
    std::printf("vs STL      %s\n", plan::exact_deviation_text(exact).c_str());
    exact_within = exact.within_tolerance();
  }
  std::printf("wrote       %s: job/, as-built.vdb, sim-report.json, executed-lines.ngc\n", out.c_str());
  return d.within_tolerance && exact_within && alarms.empty();
}

int run_dry_run(const DryRunArgs& a) {
  if (a.transport != "modbus" && a.transport != "can")
    throw InputError("--transport " + a.transport + ": expected modbus or can");
  const std::string machine_text = config::read_machine_text(a.machine);
  const config::Machine machine = gcode::parse_postable_machine(machine_text, a.machine);
  const fs::path out = a.output;
  fs::create_directories(out);

  // 1. Plan: every plan offered is proven by execution first (validation/).
  planner::PlanningOptions options;
  options.voxel_size = a.voxel;
  options.tolerance = a.tolerance;
  options.max_uses = a.reuse;
  options.memory_budget = memory_budget(a.memory_budget);
  const geometry::TriangleMesh mesh = geometry::read_stl(a.part);
  validation::ExecutionOptions proving;
  const auto surfaces = std::make_shared<verification::DesignSurfaces>(mesh, a.part);
  proving.surfaces = surfaces;
  planner::validate_by_execution(options, validation::plan_validator(machine, std::move(proving)), machine.name);
  options.stock_files = a.stock_files;
  options.objective = objective(a.objective);
  const planner::PlanningResult planned = planner::plan_part(mesh, a.part, machine, options);
  const planner::ReportSources sources{a.part, a.machine, machine.name, machine_text};
  std::fputs(planner::plan_summary(planned, sources, a.verbose).c_str(), stdout);
  if (!planned.verdict.manufacturable() || planned.plans.empty()) return kNotManufacturable;
  const fs::path plan_dir = out / "plan";
  planner::write_plan_directory(planned, sources, plan_dir);
  const plan::PlanFile file = planner::to_plan_file(planned, sources, plan_dir);
  const int plans = int(file.plans.size());
  if (!a.all && (a.plan < 1 || a.plan > plans))
    throw InputError("--plan " + std::to_string(a.plan) + ": expected 1.." + std::to_string(plans) + " (the plans offered)");

  // 2. Each chosen plan on its own simulated controller.
  int clean = 0, runs = 0;
  for (int rank = a.all ? 1 : a.plan; rank <= (a.all ? plans : a.plan); ++rank, ++runs)
    clean += dry_run_plan(a, machine, *surfaces, file, rank, out / ("plan-" + std::to_string(rank)));
  std::printf("dry-run     %d of %d plan%s ran to the end with no alarm, within tolerance both ways\n", clean, runs,
              runs == 1 ? "" : "s");
  if (a.report) {
    // The report shows what one run built: plan N's, or with --all the best plan's.
    const fs::path run = out / ("plan-" + std::to_string(a.all ? 1 : a.plan));
    report::ReportRequest request;
    request.plan = plan_dir;
    request.output = out / "report.html";
    request.as_built = run / "as-built.vdb";
    request.run_report = run / "sim-report.json";
    write_job_report(request);
  }
  return clean == runs ? int(kSuccess) : int(kMachineStopped);
}

}  // namespace

void add_dry_run_command(CLI::App& app, Runner& runner) {
  auto a = std::make_shared<DryRunArgs>();
  auto* cmd = app.add_subcommand("dry-run",
                                 "Plan a part, export the best plan (or --plan N, or --all), run each through its own "
                                 "simulated controller (a separate `hybridctl sim serve` process on 127.0.0.1) from the raw "
                                 "stock and compare as built with as planned and with the design, both ways, with every "
                                 "alarm and its line (exit 5 when a plan stopped, raised an alarm or came out of tolerance)");
  cmd->add_option("PART", a->part, "Part mesh (closed STL, mm)")->required();
  cmd->add_option("-m,--machine", a->machine, "Machine description (YAML)")->required();
  cmd->add_option("--transport", a->transport, "modbus (Modbus TCP) or can (socketcand)")->capture_default_str();
  cmd->add_option("-o,--output", a->output, "Directory for the plan, the job and the simulator's output")->capture_default_str();
  auto* plan = cmd->add_option("--plan", a->plan, "Which offered plan to run, by rank")->capture_default_str()->check(greater_than(0));
  cmd->add_flag("--all", a->all, "Run every offered plan, each on its own simulated controller from the raw stock")
      ->excludes(plan);
  cmd->add_option("--voxel", a->voxel, "Voxel size in mm (default: the machine file's)")->check(greater_than(0));
  cmd->add_option("--tolerance", a->tolerance, "Tolerance in mm, as for `plan` (default: the machine file's planning.tolerance)")
      ->check(at_least(0));
  cmd->add_option("--reuse", a->reuse, "How often one primitive may appear in a plan, as for `plan`")
      ->default_val(1)
      ->check(between(1, 8));
  add_memory_budget_option(cmd, a->memory_budget);
  cmd->add_flag("--report", a->report,
                "Also write the job report with what the run built and its alarms, DIR/report.html and its PNG snapshots");
  cmd->add_flag("--verbose", a->verbose, "As for `plan`: a refusal's proof in atoms and regions too");
  cmd->add_option("--stock", a->stock_files,
                  "Raw stock as a file (STL, or .vdb on the plan's voxel grid) in the part's frame, as for `plan`; "
                  "repeatable");
  add_objective_option(cmd, a->objective);
  cmd->add_option("--time-scale", a->time_scale, "Simulated seconds per real second (0: as fast as possible)")
      ->capture_default_str()
      ->check(at_least(0));
  cmd->callback([&runner, a] { runner = [a] { return run_dry_run(*a); }; });
}

}  // namespace hybridctl::cli
