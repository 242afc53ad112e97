// A plan directory is self-contained (docs/plan-format.md): copied anywhere and used from
// another working directory it exports the same programs, with the machine it embeds;
// --machine for another machine needs --machine-override; older plans that name their
// machine file still load. And `sim serve` refuses a stock over --memory-budget up front.

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "shell.hpp"

namespace {

namespace fs = std::filesystem;

const fs::path kSource = HYBRIDCTL_SOURCE_DIR;
const std::string kMachine = (kSource / "examples/machines/hybrid-3axis.yaml").string();

// Outcome, quote, slurp, run_shell, DirectoryTest.
using namespace hybridctl::cli_testing;

class PortablePlan : public DirectoryTest {
 protected:
  PortablePlan() : DirectoryTest("portable") {}
  void SetUp() override {
    DirectoryTest::SetUp();
    fs::create_directories(dir_ / "elsewhere");
  }

  // hybridctl ARGS run from `cwd`.
  Outcome hybridctl(const std::vector<std::string>& args, const fs::path& cwd) {
    std::string cmd = "cd " + quote(cwd.string()) + " && " + quote(HYBRIDCTL_EXE);
    for (const auto& a : args) cmd += " " + quote(a);
    return hybridctl::cli_testing::run_shell(cmd, dir_);
  }

  // The overhang planned into A with relative paths, from the source directory; then A
  // copied to B/A.
  fs::path plan_and_copy() {
    const Outcome planned = hybridctl({"plan", "--no-validate", "examples/parts/overhang.stl", "--machine", "examples/machines/hybrid-3axis.yaml",
                                       "--voxel", "0.5", "--top", "1", "-o", (dir_ / "A").string()},
                                      kSource);
    EXPECT_EQ(planned.exit_code, 0) << planned.out << planned.err;
    fs::create_directories(dir_ / "B");
    fs::copy(dir_ / "A", dir_ / "B" / "A", fs::copy_options::recursive);
    return dir_ / "B" / "A";
  }

  static std::string programs_of(const fs::path& out) {
    std::string all;
    for (const auto& entry : fs::directory_iterator(out))
      if (entry.path().extension() == ".ngc") all += entry.path().filename().string() + "\n" + slurp(entry.path());
    return all;
  }

};

TEST_F(PortablePlan, ACopiedPlanExportsTheSameProgramsFromAnotherDirectory) {
  const fs::path copied = plan_and_copy();
  const Outcome original = hybridctl({"export", (dir_ / "A/plan.json").string(), "-o", (dir_ / "out-a").string()}, kSource);
  ASSERT_EQ(original.exit_code, 0) << original.err;
  const Outcome moved = hybridctl({"export", "../B/A/plan.json", "-o", "out-b"}, dir_ / "elsewhere");
  ASSERT_EQ(moved.exit_code, 0) << moved.err;
  EXPECT_EQ(moved.err, "");
  const std::string a = programs_of(dir_ / "out-a");
  EXPECT_GT(a.size(), 1000u);
  EXPECT_EQ(a, programs_of(dir_ / "elsewhere/out-b"));

  const nlohmann::json doc = nlohmann::json::parse(slurp(copied / "plan.json"));
  EXPECT_EQ(doc["machine"]["yaml"], slurp(kMachine));
  EXPECT_EQ(doc["machine"]["hash"].get<std::string>().size(), 16u);
  EXPECT_FALSE(fs::path(doc["part"].get<std::string>()).is_absolute());
}

TEST_F(PortablePlan, AnotherMachineIsRefusedWithoutTheOverrideAndSaidWithIt) {
  const fs::path copied = plan_and_copy();
  std::ofstream(dir_ / "other.yaml") << slurp(kMachine) << "# edited after planning\n";
  const Outcome refused = hybridctl({"export", copied.string(), "-o", "out", "--machine", "../other.yaml"}, dir_ / "elsewhere");
  EXPECT_EQ(refused.exit_code, 3);
  EXPECT_NE(refused.err.find("not the machine the plan was made with"), std::string::npos) << refused.err;
  EXPECT_NE(refused.err.find("--machine-override"), std::string::npos) << refused.err;
  EXPECT_FALSE(fs::exists(dir_ / "elsewhere/out"));

  const Outcome forced =
      hybridctl({"export", copied.string(), "-o", "out", "--machine", "../other.yaml", "--machine-override"}, dir_ / "elsewhere");
  EXPECT_EQ(forced.exit_code, 0) << forced.err;
  EXPECT_NE(forced.err.find("overrides the plan's embedded machine 'hybrid-3axis'"), std::string::npos) << forced.err;
  EXPECT_EQ(std::count(forced.err.begin(), forced.err.end(), '\n'), 1) << forced.err;

  const Outcome same = hybridctl({"export", copied.string(), "-o", "out2", "--machine", kMachine}, dir_ / "elsewhere");
  EXPECT_EQ(same.exit_code, 0) << same.err;
  EXPECT_NE(same.err.find("the same machine as the plan's embedded 'hybrid-3axis'"), std::string::npos) << same.err;
}

TEST_F(PortablePlan, AnOlderPlanNamingItsMachineFileStillLoads) {
  const fs::path copied = plan_and_copy();
  nlohmann::json doc = nlohmann::json::parse(slurp(copied / "plan.json"));
  doc["machine"] = {{"name", "hybrid-3axis"}, {"file", "machines/m.yaml"}};
  std::ofstream(copied / "plan.json") << doc.dump(2);

  const Outcome nowhere = hybridctl({"export", copied.string(), "-o", "out"}, dir_ / "elsewhere");
  EXPECT_EQ(nowhere.exit_code, 3);
  EXPECT_NE(nowhere.err.find("neither in the plan's directory (" + (copied / "machines/m.yaml").string() + ")"),
            std::string::npos)
      << nowhere.err;
  EXPECT_NE(nowhere.err.find("nor in the working directory"), std::string::npos) << nowhere.err;

  // Relative to the working directory, then to plan.json's directory (which wins).
  fs::create_directories(dir_ / "elsewhere/machines");
  fs::copy_file(kMachine, dir_ / "elsewhere/machines/m.yaml");
  const Outcome from_cwd = hybridctl({"export", copied.string(), "-o", "out-cwd"}, dir_ / "elsewhere");
  EXPECT_EQ(from_cwd.exit_code, 0) << from_cwd.err;
  fs::create_directories(copied / "machines");
  fs::copy_file(kMachine, copied / "machines/m.yaml");
  const Outcome from_plan = hybridctl({"export", copied.string(), "-o", "out-plan"}, dir_);
  EXPECT_EQ(from_plan.exit_code, 0) << from_plan.err;
  EXPECT_EQ(programs_of(dir_ / "elsewhere/out-cwd"), programs_of(dir_ / "out-plan"));
}

TEST_F(PortablePlan, AnEmbeddedMachineWithTheWrongHashIsRefused) {
  const fs::path copied = plan_and_copy();
  nlohmann::json doc = nlohmann::json::parse(slurp(copied / "plan.json"));
  doc["machine"]["yaml"] = doc["machine"]["yaml"].get<std::string>() + "# edited\n";
  std::ofstream(copied / "plan.json") << doc.dump(2);
  const Outcome r = hybridctl({"export", copied.string(), "-o", "out"}, dir_);
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find("/machine/hash: expected"), std::string::npos) << r.err;
}

TEST_F(PortablePlan, SimServeRefusesAStockOverTheMemoryBudget) {
  const fs::path copied = plan_and_copy();
  for (const std::vector<std::string>& stock : {std::vector<std::string>{"--stock", copied.string()},
                                                std::vector<std::string>{"--stock-vdb", (copied / "design.vdb").string()}}) {
    std::vector<std::string> args = {"sim", "serve", "--machine", kMachine, "--modbus", "tcp://127.0.0.1:0", "--memory-budget", "4k"};
    args.insert(args.end(), stock.begin(), stock.end());
    const Outcome r = hybridctl(args, dir_);
    EXPECT_EQ(r.exit_code, 3) << stock[0];
    EXPECT_NE(r.err.find("of memory, over the budget of 4 KiB"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("or larger fits"), std::string::npos) << r.err;
    EXPECT_EQ(r.out.find("listening"), std::string::npos) << r.out;
  }
}

}  // namespace
