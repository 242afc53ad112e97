// The shop cell (docs/cell.md) against a real PostgreSQL server of the test's own on
// 127.0.0.1 (postgres_server.hpp), with `hybridctl cell` run as separate processes: the
// schema made and migrated safely twice and at once; many jobs over several plan workers,
// each planned exactly once; a worker killed mid-plan, whose job is planned again once by
// another; the database restarted under a working worker; a bad part failing its job
// while the queue goes on; a job's files written back out; bad input refused.

#include "cell_fixture.hpp"

namespace hybridctl::cell {
namespace {

namespace fs = std::filesystem;
using cell_testing::CellTest;
using cell_testing::kSource;
using cell_testing::plan_children_of;
using cell_testing::Process;
using cell_testing::running;
using cli_testing::run_shell;
using cli_testing::quote;
using cli_testing::slurp;

class Cell : public CellTest {
 protected:
  Cell() : CellTest("cell") {}
};

TEST_F(Cell, InitMakesTheSchemaOnceWhetherRunTwiceOrThreeAtOnce) {
  std::vector<std::unique_ptr<Process>> inits;
  for (int k = 0; k < 3; ++k)
    inits.push_back(std::make_unique<Process>(quote(HYBRIDCTL_EXE) + " cell init --db " + quote(server_->uri()),
                                              dir_ / ("init-" + std::to_string(k) + ".out")));
  for (int k = 0; k < 3; ++k) EXPECT_EQ(inits[std::size_t(k)]->wait(120), 0) << slurp(dir_ / ("init-" + std::to_string(k) + ".out"));
  const auto again = cell("init");
  EXPECT_EQ(again.exit_code, 0) << again.err;
  EXPECT_NE(again.out.find("schema version 2, up to date"), std::string::npos) << again.out;
  EXPECT_EQ(value("SELECT count(*) FROM cell_schema"), "2");
  EXPECT_EQ(value("SELECT count(*) FROM pg_tables WHERE tablename LIKE 'cell_%'"), "6");
  // Another role of the same server reads none of the jobs' files.
  Database db(server_->uri());
  db.exec("a role", "CREATE ROLE another_shop");
  db.exec("that role", "SET ROLE another_shop");
  try {
    db.exec("its read", "SELECT count(*) FROM cell_job_files");
    ADD_FAILURE() << "another role read the jobs' files";
  } catch (const DatabaseError& e) {
    EXPECT_EQ(e.sqlstate(), "42501") << e.what();  // insufficient_privilege
  }
}

TEST_F(Cell, TwoHundredJobsOverFourWorkersArePlannedEachExactlyOnce) {
  init_with_a_machine();
  {
    Database db(server_->uri());
    const std::string stl = slurp(box_);
    for (int k = 0; k < 199; ++k)  // as `cell submit` stores them (the 200th below is submitted by it)
      db.exec("a submission",
              "INSERT INTO cell_jobs (machine, part_name, part, machine_text, machine_hash, options) "
              "SELECT 'mill', 'box.stl', $1, machine, hash, '{\"voxel\": 2, \"top\": 1}' FROM cell_machines WHERE name = 'mill'",
              {Param::bytes(stl)});
  }
  submit(box_, "--voxel 2 --top 1");
  std::vector<std::unique_ptr<Process>> workers;
  for (int k = 0; k < 4; ++k)
    workers.push_back(std::make_unique<Process>(worker_command("--drain --name w" + std::to_string(k)),
                                                dir_ / ("w" + std::to_string(k) + ".out")));
  for (int k = 0; k < 4; ++k)
    EXPECT_EQ(workers[std::size_t(k)]->wait(1500), 0) << slurp(dir_ / ("w" + std::to_string(k) + ".out"));
  EXPECT_EQ(value("SELECT count(*) FROM cell_jobs WHERE state = 'planned' AND attempts = 1"), "200");
  EXPECT_EQ(value("SELECT count(*) FROM cell_job_events WHERE event = 'claimed'"), "200");
  EXPECT_EQ(value("SELECT count(*) FROM cell_job_events WHERE event = 'planned'"), "200");
  EXPECT_EQ(value("SELECT count(DISTINCT job) FROM cell_job_events WHERE event = 'planned'"), "200");
  EXPECT_EQ(value("SELECT count(*) FROM cell_jobs j WHERE NOT EXISTS "
                  "(SELECT 1 FROM cell_job_files f WHERE f.job = j.id AND f.path = 'plan.json')"),
            "0");
  EXPECT_GE(std::stoi(value("SELECT count(DISTINCT worker) FROM cell_jobs")), 2) << "the workers did not share the queue";
}

TEST_F(Cell, AWorkerKilledMidPlanLosesItsLeaseAndAnotherPlansTheJobOnce) {
  init_with_a_machine();
  // The flanged hub at 0.5 mm: seconds of planning, long enough to be killed in.
  const std::int64_t job = submit(kSource / "examples/parts/flanged-hub.stl", "--voxel 0.5 --top 1");
  auto first = std::make_unique<Process>(worker_command("--name first --lease 3"), dir_ / "first.out");
  ASSERT_TRUE(becomes("SELECT state FROM cell_jobs", "planning", 60)) << slurp(dir_ / "first.out");
  std::vector<pid_t> plan;
  for (int i = 0; i < 200 && plan.empty(); ++i) {
    plan = plan_children_of(first->pid);
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ASSERT_EQ(plan.size(), 1u) << "the worker started no `plan`: " << slurp(dir_ / "first.out");
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  kill(first->pid, SIGKILL);  // the worker, not its `plan` child: that one must die with it
  first->wait(10);
  bool plan_ended = false;
  for (int i = 0; i < 100 && !plan_ended; ++i) {
    plan_ended = !running(plan.front());
    if (!plan_ended) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  EXPECT_TRUE(plan_ended) << "the killed worker's `plan` plans on (PR_SET_PDEATHSIG)";
  Process second(worker_command("--drain --name second --lease 3"), dir_ / "second.out");
  EXPECT_EQ(second.wait(900), 0) << slurp(dir_ / "second.out");
  EXPECT_EQ(value("SELECT state || ' ' || attempts || ' ' || worker FROM cell_jobs WHERE id = " + std::to_string(job)),
            "planned 2 second");
  EXPECT_EQ(value("SELECT string_agg(coalesce(worker, '') || ':' || event, ' ' ORDER BY id) FROM cell_job_events"),
            ":submitted first:claimed second:claimed second:planned");
}

TEST_F(Cell, ABadPartFailsItsJobWithTheReasonAndTheQueueGoesOn) {
  init_with_a_machine();
  const fs::path bad = dir_ / "not-a-mesh.stl";
  std::ofstream(bad) << std::string(200, 'x');
  const std::int64_t bad_job = submit(bad);
  const std::int64_t good_job = submit(box_);
  Process worker(worker_command("--drain"), dir_ / "worker.out");
  EXPECT_EQ(worker.wait(600), 0) << slurp(dir_ / "worker.out");
  const std::string reason = value("SELECT state || ': ' || reason FROM cell_jobs WHERE id = " + std::to_string(bad_job));
  EXPECT_EQ(reason.rfind("failed: hybridctl: error: ", 0), 0u) << reason;
  EXPECT_NE(reason.find("not-a-mesh.stl"), std::string::npos) << reason;
  EXPECT_EQ(value("SELECT state FROM cell_jobs WHERE id = " + std::to_string(good_job)), "planned");
}

TEST_F(Cell, TheDatabaseRestartedUnderAWorkerLosesNoJobAndPlansNoneTwice) {
  init_with_a_machine();
  for (int k = 0; k < 6; ++k) submit(box_);
  Process worker(worker_command("--name steady --lease 20"), dir_ / "worker.out");
  ASSERT_TRUE(becomes("SELECT count(*) >= 1 FROM cell_jobs WHERE state = 'planned'", "t", 300)) << slurp(dir_ / "worker.out");
  server_->stop();
  std::this_thread::sleep_for(std::chrono::seconds(2));
  server_->start();
  EXPECT_TRUE(becomes("SELECT count(*) FROM cell_jobs WHERE state = 'planned'", "6", 600)) << slurp(dir_ / "worker.out");
  EXPECT_EQ(value("SELECT count(*) FROM cell_job_events WHERE event = 'planned'"), "6");
  EXPECT_EQ(value("SELECT max(attempts) FROM cell_jobs"), "1");
  EXPECT_NE(slurp(dir_ / "worker.out").find("database back"), std::string::npos) << slurp(dir_ / "worker.out");
}

TEST_F(Cell, StatusListsTheQueueAndReportWritesAJobsPlanDirectory) {
  init_with_a_machine();
  const std::int64_t job = submit(box_);
  Process worker(worker_command("--drain"), dir_ / "worker.out");
  ASSERT_EQ(worker.wait(600), 0) << slurp(dir_ / "worker.out");
  const auto status = cell("status");
  EXPECT_EQ(status.exit_code, 0) << status.err;
  EXPECT_NE(status.out.find("jobs: planned 1"), std::string::npos) << status.out;
  EXPECT_NE(status.out.find("box.stl"), std::string::npos) << status.out;
  const fs::path out = dir_ / "job";
  const auto report = cell("report " + std::to_string(job) + " -o " + quote(out.string()));
  EXPECT_EQ(report.exit_code, 0) << report.err;
  EXPECT_TRUE(fs::exists(out / "plan.json"));
  EXPECT_TRUE(fs::exists(out / "report.html"));
  EXPECT_TRUE(fs::exists(out / "plan.log"));
  // Again into the same directory: refused, nothing touched.
  const auto again = cell("report " + std::to_string(job) + " -o " + quote(out.string()));
  EXPECT_EQ(again.exit_code, 3);
  EXPECT_NE(again.err.find("exists"), std::string::npos) << again.err;
}

TEST_F(Cell, BadInputIsRefusedWithWhereAndWhat) {
  // Before `cell init`: not a cell database.
  const auto uninitialised = cell("status");
  EXPECT_EQ(uninitialised.exit_code, 3);
  EXPECT_NE(uninitialised.err.find("cell init"), std::string::npos) << uninitialised.err;
  init_with_a_machine();
  const auto unknown = cell("submit " + quote(box_.string()) + " --machine lathe");
  EXPECT_EQ(unknown.exit_code, 3);
  EXPECT_NE(unknown.err.find("--machine lathe"), std::string::npos) << unknown.err;
  const auto bad_name = cell("machines add 'a b' --machine " + quote((kSource / "examples/machines/hybrid-3axis.yaml").string()));
  EXPECT_EQ(bad_name.exit_code, 3);
  const auto bad_file = cell("machines add m2 --machine " + quote(box_.string()));
  EXPECT_EQ(bad_file.exit_code, 3) << bad_file.err;
  EXPECT_EQ(cell("report 999 -o " + quote((dir_ / "x").string())).exit_code, 3);
  // Nobody there: exit 6, naming the server without its password.
  const auto away = run_shell(quote(HYBRIDCTL_EXE) + " cell status --db 'postgresql://cell:secret@127.0.0.1:1/postgres'", dir_);
  EXPECT_EQ(away.exit_code, 6);
  EXPECT_NE(away.err.find("127.0.0.1:1"), std::string::npos) << away.err;
  EXPECT_EQ(away.err.find("secret"), std::string::npos) << away.err;
  EXPECT_FALSE(fs::exists(dir_ / "x"));
}

}  // namespace
}  // namespace hybridctl::cell
