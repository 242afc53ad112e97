// Reading plan.json back (plan/plan_file.hpp): a plan directory written here, read from
// the file and from text alike, and bad JSON refused as InputError naming the file, never
// any other exception (the fuzz target fuzz/plan_fuzz.cpp feeds the text form).

#include "plan/plan_file.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "common/error.hpp"
#include "geometry/vdb_file.hpp"

namespace hybridctl::plan {
namespace {

namespace fs = std::filesystem;

// design.vdb and primitives/P1.vdb on a 1 mm grid, and plan.json naming them.
class PlanFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("hybridctl-plan-file-" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "primitives");
    const geometry::Lattice lattice{1.0, {0, 0, 0}};
    geometry::write_vdb(geometry::Solid::filled(lattice, {{1, 1, 0}, {3, 3, 2}}), dir_ / "design.vdb", "design");
    geometry::write_vdb(geometry::Solid::filled(lattice, {{0, 0, 0}, {4, 4, 2}}), dir_ / "primitives" / "P1.vdb", "P1");
  }
  void TearDown() override { fs::remove_all(dir_); }

  // A plan.json with `tolerance` as written.
  static std::string plan_json(const std::string& tolerance) {
    return R"({"format": "hybridctl-plan", "version": 1, "part": "p.stl",
               "machine": {"name": "m", "file": "m.yaml"},
               "grid": {"voxel_size": 1.0, "origin": [0, 0, 0], "domain": {"lo": [0, 0, 0], "hi": [4, 4, 4]}},
               "design": {"file": "design.vdb"}, "tolerance": )" +
           tolerance + R"(,
               "primitives": [{"name": "P1", "label": "stock", "kind": "raw-stock", "mode": "additive",
                               "capability": "plate", "setup": "", "file": "primitives/P1.vdb"}],
               "plans": [{"rank": 1, "expression": "P1", "cost": 0.5,
                          "actions": [{"primitive": "P1", "volume": 32, "cost": 0.5}]}]})";
  }

  std::string error_of(const std::string& text) const {
    try {
      parse_plan_file(text, dir_ / "plan.json");
    } catch (const InputError& e) {
      return e.what();
    }
    ADD_FAILURE() << "expected an InputError for: " << text;
    return {};
  }

  fs::path dir_;
};

TEST_F(PlanFileTest, TheFileAndItsTextReadAlike) {
  std::ofstream(dir_ / "plan.json") << plan_json("0.25");
  const PlanFile from_file = read_plan_file(dir_);
  const PlanFile from_text = parse_plan_file(plan_json("0.25"), dir_ / "plan.json");
  for (const PlanFile* f : {&from_file, &from_text}) {
    EXPECT_EQ(f->tolerance, 0.25);
    ASSERT_EQ(f->primitives.size(), 1u);
    EXPECT_EQ(f->primitives[0].region.voxel_count(), 32);
    EXPECT_EQ(f->design.voxel_count(), 8);
    ASSERT_EQ(f->plans.size(), 1u);
    ASSERT_EQ(f->plans[0].actions.size(), 1u);
    EXPECT_EQ(f->plans[0].actions[0].primitive, 0);
  }
  EXPECT_EQ(from_file.directory, from_text.directory);
}

TEST_F(PlanFileTest, BadJsonIsAnInputErrorNamingTheFile) {
  const std::string name = (dir_ / "plan.json").string();
  const std::string syntax = error_of(plan_json("0.25,"));
  EXPECT_EQ(syntax.rfind(name + ": not JSON: ", 0), 0u) << syntax;
  EXPECT_NE(syntax.find("parse error at line 4, column"), std::string::npos) << syntax;
  // Found by fuzz/plan_fuzz (fuzz/corpus/plan/errors.json): a number beyond a double's
  // range made nlohmann::json throw out_of_range, which escaped as std::terminate.
  const std::string overflow = error_of(plan_json("1e999"));
  EXPECT_EQ(overflow.rfind(name + ": not JSON: ", 0), 0u) << overflow;
  EXPECT_NE(overflow.find("number overflow parsing '1e999'"), std::string::npos) << overflow;
}

TEST_F(PlanFileTest, WrongValuesNameTheirJsonLocation) {
  const std::string name = (dir_ / "plan.json").string();
  EXPECT_EQ(error_of(plan_json("\"half\"")), name + ": /tolerance: expected a number, found \"half\"");
  EXPECT_EQ(error_of("[1, 2]"), name + ": /: expected an object, found [1,2]");
}

}  // namespace
}  // namespace hybridctl::plan
