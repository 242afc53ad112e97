// The hybridctl program as a user meets it: exit codes (0 success, 2 usage, 3 bad
// input), messages on stderr that say where and what was expected, help everywhere,
// and no output file left behind when something fails.

#include <gtest/gtest.h>

#include <algorithm>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <regex>
#include "shell.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>

#include "geometry/mesh.hpp"
#include "geometry/vdb_file.hpp"

namespace {

namespace fs = std::filesystem;

using hybridctl::cli_testing::Outcome;
using hybridctl::cli_testing::quote;
using hybridctl::cli_testing::slurp;

class Cli : public hybridctl::cli_testing::DirectoryTest {
 protected:
  Cli() : DirectoryTest("cli") {}
  Outcome run(const std::vector<std::string>& args) { return run_hybridctl(args); }

  fs::path write(const std::string& name, const std::string& bytes) {
    std::ofstream(dir_ / name, std::ios::binary) << bytes;
    return dir_ / name;
  }

};

const std::string kBracket = std::string(HYBRIDCTL_SOURCE_DIR) + "/examples/parts/bracket.stl";
const std::string kFlangedHub = std::string(HYBRIDCTL_SOURCE_DIR) + "/examples/parts/flanged-hub.stl";

TEST_F(Cli, EverySubcommandHasHelp) {
  for (auto args : std::vector<std::vector<std::string>>{
           {"--help"}, {"machine", "--help"}, {"machine", "check", "--help"}, {"voxelize", "--help"}, {"inspect", "--help"}, {"plan", "--help"},
           {"gcode", "--help"}, {"gcode", "check", "--help"}}) {
    const Outcome r = run(args);
    EXPECT_EQ(r.exit_code, 0) << args[0];
    EXPECT_NE(r.out.find("Usage"), std::string::npos) << r.out;
  }
}

TEST_F(Cli, UsageErrorsExitWithTwo) {
  EXPECT_EQ(run({}).exit_code, 2);
  EXPECT_EQ(run({"frobnicate"}).exit_code, 2);
  EXPECT_EQ(run({"voxelize", kBracket}).exit_code, 2);  // -o missing
  const Outcome negative = run({"voxelize", kBracket, "--voxel", "-1", "-o", (dir_ / "x.vdb").string()});
  EXPECT_EQ(negative.exit_code, 2);
  EXPECT_NE(negative.err.find("--voxel"), std::string::npos) << negative.err;
  EXPECT_FALSE(fs::exists(dir_ / "x.vdb"));
}

TEST_F(Cli, VoxelizesThePartAndWritesTheVdbAndSlices) {
  const Outcome r = run({"voxelize", kBracket, "--voxel", "1", "-o", (dir_ / "b.vdb").string(), "--png-slices",
                     (dir_ / "slices").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("volume"), std::string::npos) << r.out;
  const auto solid = hybridctl::geometry::read_vdb(dir_ / "b.vdb");
  EXPECT_DOUBLE_EQ(solid.voxel_size(), 1.0);
  EXPECT_GT(solid.voxel_count(), 1000);
  const auto layers = solid.bounding_box().hi.z - solid.bounding_box().lo.z;
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_ / "slices"), fs::directory_iterator{}), layers);
  const Outcome inspect = run({"inspect", (dir_ / "b.vdb").string()});
  EXPECT_EQ(inspect.exit_code, 0) << inspect.err;
  EXPECT_NE(inspect.out.find(std::to_string(solid.voxel_count())), std::string::npos) << inspect.out;
}

TEST_F(Cli, InspectsAMesh) {
  const Outcome r = run({"inspect", kBracket});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("closed       yes"), std::string::npos) << r.out;
}

struct BadStl {
  const char* name;
  std::string bytes;
  const char* says;
};

std::string cube_binary(std::size_t keep_bytes = std::string::npos) {
  std::string bytes(80, '\0');
  const std::uint32_t n = 12;
  bytes.append(reinterpret_cast<const char*>(&n), 4);
  bytes.append(12 * 50, '\0');
  return bytes.substr(0, keep_bytes);
}

TEST_F(Cli, EachBadStlKindGetsItsOwnMessageAndExitCodeThree) {
  std::string nan_bytes = cube_binary();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(nan_bytes.data() + 84 + 12, &nan, 4);
  std::string garbage(3000, '\0');
  for (std::size_t i = 0; i < garbage.size(); ++i) garbage[i] = char((i * 7919) % 251);
  const std::vector<BadStl> cases = {
      {"empty.stl", "", "empty file"},
      {"short.stl", std::string(50, 'x'), "truncated: 50 bytes"},
      {"truncated.stl", cube_binary(400), "truncated: the binary STL header announces 12 triangles"},
      {"toolong.stl", cube_binary() + "extra", "size mismatch"},
      {"nan.stl", nan_bytes, "non-finite coordinate"},
      {"garbage.stl", garbage, "not an ASCII STL either"},
      {"ascii.stl", "solid x\nfacet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 1 0 zero\n", "ascii.stl:5:14: expected a vertex coordinate"},
      {"open.stl", "solid x\nfacet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 1 0 0\n  vertex 0 1 0\n endloop\nendfacet\nendsolid\n", "open mesh: 3 boundary edges"},
  };
  for (const BadStl& c : cases) {
    const fs::path input = write(c.name, c.bytes);
    const fs::path output = dir_ / (std::string(c.name) + ".vdb");
    const Outcome r = run({"voxelize", input.string(), "-o", output.string()});
    EXPECT_EQ(r.exit_code, 3) << c.name << ": " << r.err;
    EXPECT_NE(r.err.find(c.says), std::string::npos) << c.name << ": " << r.err;
    EXPECT_NE(r.err.find(input.string()), std::string::npos) << c.name << " message does not name the file: " << r.err;
    EXPECT_FALSE(fs::exists(output)) << c.name;
  }
}

TEST_F(Cli, AnOutputDirectoryThatDoesNotExistIsBadInputAndNothingIsWritten) {
  const Outcome r = run({"voxelize", kBracket, "--voxel", "2", "-o", (dir_ / "nope" / "b.vdb").string()});
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find("does not exist"), std::string::npos) << r.err;
}

TEST_F(Cli, MachineCheckAcceptsTheExamplesAndPointsAtEveryProblem) {
  for (const char* machine : {"hybrid-3axis.yaml", "multitask-b-axis.yaml"}) {
    const Outcome ok = run({"machine", "check", std::string(HYBRIDCTL_SOURCE_DIR) + "/examples/machines/" + machine});
    EXPECT_EQ(ok.exit_code, 0) << machine << ": " << ok.err;
  }
  const fs::path bad = write("bad.yaml", "name: broken\nenvelope:\n  x: [0, 100]\n  y: [0, 100]\n  z: [0, 100]\nfrobnicate: 3\n");
  const Outcome r = run({"machine", "check", bad.string()});
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find(bad.string() + ":6:1:"), std::string::npos) << r.err;
}

// The mill-turn's file told to write for LinuxCNC: its spindle code M203 is not LinuxCNC's.
// `plan` refuses the file before planning (exit 3), at the code's line, and writes nothing.
TEST_F(Cli, AMachineFileThatCannotPostIsRefusedBeforePlanningAtItsLine) {
  std::string text = slurp(std::string(HYBRIDCTL_SOURCE_DIR) + "/examples/machines/multitask-b-axis.yaml");
  text.replace(text.find("dialect: fanuc"), 14, "dialect: rs274ngc");
  const int line = 1 + int(std::count(text.begin(), text.begin() + std::ptrdiff_t(text.find("M203")), '\n'));
  const fs::path machine = write("b-axis-for-linuxcnc.yaml", text);
  const Outcome planned = run({"plan", std::string(HYBRIDCTL_SOURCE_DIR) + "/examples/parts/flanged-hub.stl", "--machine",
                               machine.string(), "-o", (dir_ / "plan").string()});
  EXPECT_EQ(planned.exit_code, 3) << planned.err;
  EXPECT_NE(planned.err.find(machine.string() + ":" + std::to_string(line) + ":"), std::string::npos) << planned.err;
  EXPECT_NE(planned.err.find("spindle_cw M203 is not the code LinuxCNC runs"), std::string::npos) << planned.err;
  EXPECT_FALSE(fs::exists(dir_ / "plan"));
  const Outcome checked = run({"machine", "check", machine.string()});
  EXPECT_EQ(checked.exit_code, 3);
  EXPECT_NE(checked.err.find(machine.string() + ":" + std::to_string(line) + ":"), std::string::npos) << checked.err;
}

}  // namespace

namespace {

const std::string kMachine = std::string(HYBRIDCTL_SOURCE_DIR) + "/examples/machines/hybrid-3axis.yaml";
const std::string kBAxisMachine = std::string(HYBRIDCTL_SOURCE_DIR) + "/examples/machines/multitask-b-axis.yaml";
const std::string kParts = std::string(HYBRIDCTL_SOURCE_DIR) + "/examples/parts/";

// The B-axis machine's primitives (issue 15): the bound that prices removals with the
// design they cut proves the block milled to the bracket optimal, or within a few percent
// of it (with a band of a voxel, plan/planning_band.hpp, more atoms are free and the exact
// search may stop at its limit; weighted A* then finds it with its gap).
TEST_F(Cli, TheBracketOnTheBAxisMachineIsMilledFromTheBlockWithinAProvenGap) {
  // The search alone.
  const Outcome r = run({"plan", kBracket, "--machine", kBAxisMachine, "--top", "1", "--no-validate", "-o", (dir_ / "plan").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
  EXPECT_TRUE(r.out.find("% of optimal (proven)") != std::string::npos ||
              r.out.find(", proven optimal") != std::string::npos)
      << r.out;
  // The first action is the block (P2), not a deposit finished by milling.
  const std::size_t first = r.out.find("  1. (");
  ASSERT_NE(first, std::string::npos) << r.out;
  EXPECT_EQ(r.out.compare(r.out.find('P', first), 3, "P2 "), 0) << r.out;
}

// The overhang's slab hangs 15 mm out on every side of its column. On the B-axis machine
// every atom of it has some deposit that lays it and none straddles the design, so only a
// search could say whether they combine, and it never finished (UNDECIDED after 30 s).
// The proof from a few atoms says before any search that they do not, and names them.
TEST_F(Cli, TheOverhangOnTheBAxisMachineIsProvenImpossibleBeforeAnySearch) {
  const Outcome r = run({"plan", kParts + "overhang.stl", "--machine", kBAxisMachine, "-o", (dir_ / "plan").string()});
  EXPECT_EQ(r.exit_code, 4) << r.err << r.out;
  EXPECT_TRUE(std::regex_search(r.out, std::regex("\nverdict     NOT manufacturable: no sequence of the [0-9]+ primitives gets these")))
      << r.out;
  EXPECT_NE(r.out.find("(must be made), in "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("(must be left empty), in "), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("rejected"), std::string::npos) << r.out;
  // The machine file's 0.3 mm is below its 0.5 mm voxel: the voxels are judged within a
  // band of a voxel, the part against the STL at 0.3 mm.
  EXPECT_NE(r.out.find("tolerance 0.3 mm on the STL's surface (the voxels are judged within a band of 0.5 mm)"),
            std::string::npos)
      << r.out;
  const std::string json = slurp(dir_ / "plan" / "plan.json");
  EXPECT_NE(json.find("\"proof\": "), std::string::npos);
  EXPECT_NE(json.find("\"violations\": [\n"), std::string::npos);
}

// The bladed disc's blades meet its hub in inside corners of 93.7 degrees. On the B-axis
// machine at its own 0.3 mm, no cutter gets within the tolerance of the eight beside the
// blades off the axes (the 4 mm cutter from above leaves 0.57 mm; the ones along X and Y
// look across them), and its powder head lays walls within 0.31 mm at best. Every
// candidate came off the machine 0.59 mm out there, and the search ran to its limit
// (UNDECIDED, 112 s); the part is refused before the search, the corners named.
TEST_F(Cli, TheBladedDiscIsRefusedOnTheBAxisMachineForTheInsideCornersAtItsBladesRoots) {
  const Outcome r = run({"plan", kParts + "bladed-disc.stl", "--machine", kBAxisMachine, "-o", (dir_ / "plan").string()});
  EXPECT_EQ(r.exit_code, 4) << r.err << r.out;
  EXPECT_NE(r.out.find("\nin words    the inside corner at ("), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("and 6 more such corners (plan.json's verdict.unreached_corners)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("and no head lays a wall within 0.3 mm as deposited: "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("ded within 0.31 mm (its accuracy 0.25 mm and half its layers' 0.12 mm scallop)"),
            std::string::npos)
      << r.out;
  EXPECT_EQ(r.out.find("rejected"), std::string::npos) << r.out;
  const std::string json = slurp(dir_ / "plan" / "plan.json");
  std::size_t corners = 0;
  for (std::size_t at = json.find("\"air_angle_deg\""); at != std::string::npos; at = json.find("\"air_angle_deg\"", at + 1))
    ++corners;
  EXPECT_EQ(corners, 8u);
  EXPECT_NE(json.find("\"outcome\": \"not-manufacturable\""), std::string::npos);
}

// A refusal a shop can read: the lidded channel's closed space in shop words, and the
// proof in atoms and regions (the planner's language) in plan.json and behind --verbose.
TEST_F(Cli, ARefusalIsSaidInShopWordsWithItsProofInAtomsBehindVerbose) {
  const Outcome r = run({"plan", kParts + "lidded-channel-block.stl", "--machine", kBAxisMachine, "-o", (dir_ / "plan").string()});
  EXPECT_EQ(r.exit_code, 4) << r.err << r.out;
  EXPECT_NE(r.out.find("\nverdict     NOT manufacturable (in words below; the proof in atoms and regions: plan.json's "
                       "verdict, or --verbose)\n"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("\nin words    closed space: a 2560 mm³ cavity around (25.0, 15.0, 16.0) mm "), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("(must be made), in "), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("atoms right together"), std::string::npos) << r.out;
  EXPECT_NE(slurp(dir_ / "plan" / "plan.json").find("\"violations\": [\n"), std::string::npos);

  const Outcome verbose = run({"plan", kParts + "lidded-channel-block.stl", "--machine", kBAxisMachine, "--verbose"});
  EXPECT_EQ(verbose.exit_code, 4) << verbose.err << verbose.out;
  EXPECT_NE(verbose.out.find("\nverdict     NOT manufacturable: no sequence of the "), std::string::npos) << verbose.out;
  EXPECT_NE(verbose.out.find("\nin words    closed space: "), std::string::npos) << verbose.out;
  EXPECT_NE(verbose.out.find("(must be left empty), in "), std::string::npos) << verbose.out;
}

// A tube on a plate on the B-axis machine, with a tolerance of one voxel: the bore's edge
// with the plate is a sharp concave ring whose voxels a cutter's sweep on the grid misses
// here and there, so the atom kept clear there is one beside it that the 12 mm flat
// clears (planner/atoms/thin_parts.hpp). Milled from the block: the search alone.
TEST_F(Cli, TheTubeOnAPlateIsMilledFromTheBlockOnTheBAxisMachineAtAToleranceOfAVoxel) {
  const Outcome r = run({"plan", kParts + "tube-plate.stl", "--machine", kBAxisMachine, "--tolerance", "0.5", "--no-validate"});
  ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
  EXPECT_NE(r.out.find("plans       3 ("), std::string::npos) << r.out;
  EXPECT_TRUE(std::regex_search(r.out, std::regex("\n  1\\. \\(+P2 \u2212 "))) << r.out;  // from the block
  EXPECT_NE(r.out.find("proven optimal"), std::string::npos) << r.out;
}

// A wall leaning 30 degrees on hybrid-3axis, deposited on its milled base: each layer's
// contour bead runs along the wall's faces, so the outer face, which no cutter from above
// reaches, is laid within tolerance as it is (rasters alone left it notched and spilled
// under it, and all 200 candidates were turned down in 15 s).
//
// Its outer face stays as deposited, judged on the STL with the powder head's 0.25 mm
// (docs/verification.md). Each layer follows the wall's section in the middle of its
// bead's full width, so the layers' staircase straddles the leaning faces: taken where the
// layer's voxel centres were, it stood 0.39 mm out of them as modelled, beyond the
// machine's 0.5 mm with the head's accuracy, and every candidate was refused.
TEST_F(Cli, ALeaningWallIsDepositedOnItsMilledBaseWithinTheToleranceAsDeposited) {
  const Outcome r = run({"plan", kParts + "leaning-wall.stl", "--machine", kMachine});
  ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
  // The best plan deposits the wall (P3, the near-net deposit from +Z) on its milled base.
  EXPECT_TRUE(std::regex_search(r.out, std::regex("\n  1\\. [^\n]*\\) \u222A P3\\)"))) << r.out;
  std::size_t plans = 0;
  const std::regex exact(R"(\n     exact:     excess (\d+\.\d+) mm at [^\n]*as deposited, gouge (\d+\.\d+) mm [^\n]*: within tolerance)");
  for (std::sregex_iterator it(r.out.begin(), r.out.end(), exact), end; it != end; ++it, ++plans) {
    EXPECT_LE(std::stod((*it)[1]), 0.5) << r.out;
    EXPECT_LE(std::stod((*it)[2]), 0.5) << r.out;
  }
  EXPECT_GE(plans, 1u) << r.out;
  EXPECT_EQ(r.out.find("OUTSIDE"), std::string::npos) << r.out;
}

TEST_F(Cli, PlansTheFlangedHubAndWritesPlanJsonWithValidPlans) {
  const Outcome r = run({"plan", "--no-validate", kFlangedHub, "--machine", kMachine, "--voxel", "1", "-o", (dir_ / "plan").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
  EXPECT_NE(r.out.find("verdict     manufacturable"), std::string::npos) << r.out;
  const std::string json = slurp(dir_ / "plan" / "plan.json");
  EXPECT_NE(json.find("\"format\": \"hybridctl-plan\""), std::string::npos);
  EXPECT_NE(json.find("\"version\": 1"), std::string::npos);
  // At least two plans, each within tolerance.
  std::size_t plans = 0, within = 0;
  for (std::size_t at = json.find("\"rank\":"); at != std::string::npos; at = json.find("\"rank\":", at + 1)) ++plans;
  for (std::size_t at = json.find("\"within_tolerance\": true"); at != std::string::npos;
       at = json.find("\"within_tolerance\": true", at + 1))
    ++within;
  EXPECT_GE(plans, 2u);
  EXPECT_EQ(within, plans);
  EXPECT_TRUE(fs::exists(dir_ / "plan" / "design.vdb"));
  EXPECT_TRUE(fs::exists(dir_ / "plan" / "primitives" / "P1.vdb"));
  EXPECT_TRUE(fs::exists(dir_ / "plan" / "plans" / "plan-1.vdb"));
  // Planning again over the earlier output replaces it.
  EXPECT_EQ(run({"plan", "--no-validate", kFlangedHub, "--machine", kMachine, "--voxel", "1", "--top", "2", "-o", (dir_ / "plan").string()}).exit_code, 0);
}

// The bracket's horizontal hole has a roof that no deposit from +Z holds up (it overhangs
// far past the head's 30 degrees) and that a deposit from -Z, turned over, could only lay
// under the material already there. The planner proves, before any search, that no order
// of its primitives makes the roof, the hole and what carries them right together, and
// names the roof, without offering validation a plan that must fail. In shop words: the
// hole can only be cut from the sides, and the machine has no setup there.
TEST_F(Cli, TheBracketIsProvenNotManufacturableOnTheThreeAxisMachineAndTheHoleRoofIsNamed) {
  const Outcome words = run({"plan", kBracket, "--machine", kMachine, "--voxel", "1"});
  EXPECT_EQ(words.exit_code, 4) << words.err << words.out;
  EXPECT_NE(words.out.find("\nin words    a 800 mm³ region around (5.0, 20.0, 35.0) mm can only be cut from +X and -X, and "
                           "the machine has no setup from any of them"),
            std::string::npos)
      << words.out;
  const Outcome r = run({"plan", kBracket, "--machine", kMachine, "--voxel", "1", "--verbose"});
  EXPECT_EQ(r.exit_code, 4) << r.err << r.out;
  EXPECT_NE(r.out.find("verdict     NOT manufacturable: no sequence of the 18 primitives gets these"), std::string::npos)
      << r.out;
  EXPECT_EQ(r.out.find("rejected"), std::string::npos) << r.out;
  // The roof of the 10 mm hole through the wall (x 0..10, y 20, z 35): its top is at z 40.
  EXPECT_NE(r.out.find("region of the design around (5.0, 20.0, 40."), std::string::npos) << r.out;
  // ... and the hole itself.
  EXPECT_NE(r.out.find("region outside the design around (5.0, 20.0, 35.0) mm (must be left empty)"), std::string::npos)
      << r.out;
}

TEST_F(Cli, PlanRefusesToReplaceADirectoryThatIsNotAPlan) {
  write("precious.txt", "keep me");
  const Outcome r = run({"plan", "--no-validate", kBracket, "--machine", kMachine, "--voxel", "1", "-o", dir_.string()});
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find("refusing to replace"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(dir_ / "precious.txt"), "keep me");
}

TEST_F(Cli, APartTheMachineCannotMakeExitsWithFour) {
  // Only a cutting tool and no stock: nothing can put material down first.
  const fs::path machine = write("mill-only.yaml",
                                 "name: mill-only\n"
                                 "envelope:\n"
                                 "  X: {travel: [0, 300]}\n  Y: {travel: [0, 300]}\n  Z: {travel: [0, 300]}\n"
                                 "tools:\n  - {number: 1, type: flat, diameter: 6}\n"
                                 "setups:\n  - {name: top, approach: +Z}\n"
                                 "raw_stocks: []\n");
  const Outcome r = run({"plan", kBracket, "--machine", machine.string(), "--voxel", "2", "--tolerance", "2"});
  EXPECT_EQ(r.exit_code, 4) << r.err << r.out;
  EXPECT_NE(r.out.find("NOT manufacturable"), std::string::npos) << r.out;
}

TEST_F(Cli, PlanArgumentsAreChecked) {
  EXPECT_EQ(run({"plan", kBracket}).exit_code, 2);  // --machine missing
  const Outcome bad = run({"plan", kBracket, "--machine", kMachine, "--primitive", "x.stl:maybe"});
  EXPECT_EQ(bad.exit_code, 3);
  EXPECT_NE(bad.err.find("expected FILE:am or FILE:sm"), std::string::npos) << bad.err;
  const Outcome missing = run({"plan", kBracket, "--machine", kMachine, "--voxel", "2", "--primitive", "/nonexistent.stl:am"});
  EXPECT_EQ(missing.exit_code, 3);
  EXPECT_NE(missing.err.find("/nonexistent.stl"), std::string::npos) << missing.err;
}

TEST_F(Cli, PrimitivesMayComeFromFiles) {
  // The part itself as an additive primitive: one deposition makes it exactly.
  const Outcome r = run({"plan", "--no-validate", kBracket, "--machine", kMachine, "--voxel", "2", "--primitive", kBracket + ":am", "-o",
                         (dir_ / "p").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("additive primitive from " + kBracket), std::string::npos) << r.out;
}

}  // namespace

namespace {

const std::string kHybrid3Axis = std::string(HYBRIDCTL_SOURCE_DIR) + "/examples/machines/hybrid-3axis.yaml";

TEST_F(Cli, GcodeCheckReportsACleanProgramAndExitsWithZero) {
  // hybrid-3axis: work zero of G54 at machine (200, 150, 0).
  const auto file = write("ok.ngc", "G21 G90 G17 G94\nG54\nT1 M6\nS8000 M3\nG0 X0 Y0 Z10\nG1 Z2 F300\n"
                                    "G2 X0 Y0 I10 J0 F1200\nG0 Z20\nM5\nM2\n");
  const Outcome r = run({"gcode", "check", file.string(), "--machine", kHybrid3Axis});
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("10 lines, 4 moves (2 rapid, 1 feed, 1 arc)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("cycle time: "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("ok.ngc: clean"), std::string::npos) << r.out;
}

TEST_F(Cli, GcodeCheckListsErrorsAndViolationsByLineAndExitsWithThree) {
  const auto file = write("bad.ngc", "G21 G90\nT1 M6\nS8000 M3\nG0 X0 Y0 Z10\nG1 X10\nG0 X250\nT42 M6\nM2\n");
  const Outcome r = run({"gcode", "check", file.string(), "--machine", kHybrid3Axis});
  EXPECT_EQ(r.exit_code, 3) << r.out << r.err;
  EXPECT_NE(r.out.find("bad.ngc:5:1: error: found G1 with zero feed rate"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("bad.ngc:6: outside the envelope: X reaches 450, beyond the X travel [0, 400]"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("bad.ngc:7:5: unknown tool: T42"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("bad.ngc: 3 problems"), std::string::npos) << r.out;
}

TEST_F(Cli, GcodeCheckArgumentAndFileErrors) {
  const auto file = write("ok.ngc", "M2\n");
  EXPECT_EQ(run({"gcode", "check", file.string()}).exit_code, 2);  // --machine is required
  const Outcome missing = run({"gcode", "check", (dir_ / "nope.ngc").string(), "--machine", kHybrid3Axis});
  EXPECT_EQ(missing.exit_code, 3);
  EXPECT_NE(missing.err.find("nope.ngc: cannot read: No such file or directory"), std::string::npos) << missing.err;
  const Outcome bad_machine = run({"gcode", "check", file.string(), "--machine", file.string()});
  EXPECT_EQ(bad_machine.exit_code, 3);
}

}  // namespace

namespace {

// Range errors say the range as a person writes it, in one short line.
TEST_F(Cli, RangeErrorsSayTheRangeInWords) {
  const Outcome zero = run({"plan", kBracket, "--machine", kMachine, "--voxel", "0"});
  EXPECT_EQ(zero.exit_code, 2);
  EXPECT_NE(zero.err.find("--voxel must be greater than 0 (got 0)"), std::string::npos) << zero.err;
  EXPECT_LT(zero.err.size(), 200u) << zero.err;
  const Outcome reuse = run({"plan", kBracket, "--machine", kMachine, "--reuse", "9"});
  EXPECT_NE(reuse.err.find("--reuse must be between 1 and 8 (got 9)"), std::string::npos) << reuse.err;
  const Outcome tolerance = run({"plan", kBracket, "--machine", kMachine, "--tolerance", "-1"});
  EXPECT_NE(tolerance.err.find("--tolerance must be at least 0 (got -1)"), std::string::npos) << tolerance.err;
  const Outcome scale = run({"sim", "serve", "--machine", kMachine, "--time-scale", "2e6"});
  EXPECT_NE(scale.err.find("--time-scale must be between 0 and 1000000 (got 2e6)"), std::string::npos) << scale.err;
}

// Peak resident memory of a child command, from /usr/bin/time -v (KiB).
long peak_rss_kib(const std::string& err) {
  const auto at = err.find("Maximum resident set size (kbytes): ");
  return at == std::string::npos ? -1 : std::stol(err.substr(at + 36));
}

// A voxel far too small for the memory is an input error found before any grid: exit 3
// at once, with the estimate, the budget and a voxel that fits, and no large allocation.
TEST_F(Cli, AVoxelTooSmallForTheMemoryIsRefusedBeforeAllocating) {
  ASSERT_EQ(std::system("test -x /usr/bin/time"), 0) << "/usr/bin/time is missing: run scripts/setup (Debian package time)";
  const auto timed = [&](std::vector<std::string> args) {
    std::string cmd = "/usr/bin/time -v " + quote(HYBRIDCTL_EXE);
    for (const auto& a : args) cmd += " " + quote(a);
    return hybridctl::cli_testing::run_shell(cmd, dir_);
  };
  const Outcome baseline = timed({"machine", "check", kMachine});
  const auto started = std::chrono::steady_clock::now();
  const Outcome r = timed({"plan", kBracket, "--machine", kMachine, "--voxel", "0.01"});
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_LT(seconds, 20.0);
  std::smatch m;
  ASSERT_TRUE(std::regex_search(r.err, m,
                                std::regex(R"(needs about ([0-9.]+) GiB of memory, over the budget of ([0-9.]+) GiB .*--voxel ([0-9.]+) or larger fits)")))
      << r.err;
  EXPECT_GT(std::stod(m[1]), std::stod(m[2]));
  EXPECT_LE(peak_rss_kib(r.err), peak_rss_kib(baseline.err) + 16 * 1024) << r.err << baseline.err;
  // A small budget is said in its own units.
  const Outcome small = run({"voxelize", kBracket, "--voxel", "0.05", "--memory-budget", "20M", "-o", (dir_ / "x.vdb").string()});
  EXPECT_EQ(small.exit_code, 3) << small.err;
  EXPECT_NE(small.err.find("over the budget of 20.0 MiB"), std::string::npos) << small.err;
  EXPECT_FALSE(fs::exists(dir_ / "x.vdb"));
  const Outcome bad = run({"plan", kBracket, "--machine", kMachine, "--memory-budget", "lots"});
  EXPECT_EQ(bad.exit_code, 3);
  EXPECT_NE(bad.err.find("expected a size greater than 0 such as 8G"), std::string::npos) << bad.err;
}

}  // namespace
