// plan::plan_machine: the embedded machine is parsed with plan.json named in its
// errors; --machine is compared by the hash of its text.

#include "plan/plan_machine.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "common/error.hpp"
#include "config/diagnostic.hpp"
#include "config/machine_loader.hpp"

namespace {

namespace fs = std::filesystem;
using namespace hybridctl;

const std::string kMachine = HYBRIDCTL_SOURCE_DIR "/examples/machines/hybrid-3axis.yaml";

plan::PlanFile embedding(const std::string& yaml) {
  plan::PlanFile f;
  f.directory = "somewhere/plan";
  f.machine_name = "hybrid-3axis";
  f.machine_yaml = yaml;
  f.machine_hash = plan::machine_text_hash(yaml);
  return f;
}

TEST(PlanMachine, TheHashIsFnv1a64InHex) {
  EXPECT_EQ(plan::machine_text_hash(""), "cbf29ce484222325");
  EXPECT_EQ(plan::machine_text_hash("a"), "af63dc4c8601ec8c");
}

TEST(PlanMachine, AnEmbeddedMachineWithProblemsNamesPlanJson) {
  try {
    plan::plan_machine(embedding("name: [unclosed\n"), {});
    FAIL() << "expected MachineFileError";
  } catch (const config::MachineFileError& e) {
    EXPECT_NE(std::string(e.what()).find("somewhere/plan/plan.json (embedded machine):"), std::string::npos) << e.what();
  }
}

TEST(PlanMachine, TheSameMachineFileIsTakenAndSaidSo) {
  const plan::PlanMachine m = plan::plan_machine(embedding(config::read_machine_text(kMachine)), {kMachine, false});
  EXPECT_EQ(m.machine.name, "hybrid-3axis");
  EXPECT_EQ(m.file, kMachine);
  EXPECT_NE(m.note.find("the same machine"), std::string::npos) << m.note;
  const plan::PlanMachine embedded = plan::plan_machine(embedding(config::read_machine_text(kMachine)), {});
  EXPECT_TRUE(embedded.file.empty());
  EXPECT_TRUE(embedded.note.empty());
}

TEST(PlanMachine, AnotherMachineNeedsTheOverride) {
  const plan::PlanFile f = embedding(config::read_machine_text(kMachine) + "# another\n");
  EXPECT_THROW(plan::plan_machine(f, {kMachine, false}), InputError);
  const plan::PlanMachine m = plan::plan_machine(f, {kMachine, true});
  EXPECT_NE(m.note.find("overrides"), std::string::npos) << m.note;
}

}  // namespace
