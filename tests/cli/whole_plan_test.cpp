// Parts planned, exported and judged end to end at the machines' own settings, as a user
// would: the plans offered executed from the raw stock on their own simulated controllers
// and judged against the STL. Each is a whole run of the pipeline over several plans (a
// minute in the everyday build, up to a quarter of an hour under the sanitizers), so they
// carry the ctest label `whole-plan`, which the sanitizer suite leaves out
// (docs/hardening.md): the code they run is under the sanitizers in the smaller plans of
// cli_test.cpp, export_test.cpp, run_test.cpp and tests/validation, and LinuxCNC's rs274
// reads exported programs there too (ArcExport, Export.TheFlangedHubDepositedThenMilled...).

#include <gtest/gtest.h>

#include <filesystem>
#include <regex>
#include <string>
#include <vector>

#include "shell.hpp"

namespace {

namespace fs = std::filesystem;

using hybridctl::cli_testing::Outcome;
using hybridctl::cli_testing::quote;
using hybridctl::cli_testing::run_shell;
using hybridctl::cli_testing::slurp;

class WholePlan : public hybridctl::cli_testing::DirectoryTest {
 protected:
  WholePlan() : DirectoryTest("whole-plan") {}
  Outcome run(const std::vector<std::string>& args) { return run_hybridctl(args); }
};

const std::string kFlangedHub = std::string(HYBRIDCTL_SOURCE_DIR) + "/examples/parts/flanged-hub.stl";
const std::string kMachine = std::string(HYBRIDCTL_SOURCE_DIR) + "/examples/machines/hybrid-3axis.yaml";
const std::string kBAxisMachine = std::string(HYBRIDCTL_SOURCE_DIR) + "/examples/machines/multitask-b-axis.yaml";
const std::string kParts = std::string(HYBRIDCTL_SOURCE_DIR) + "/examples/parts/";

// The slots on the B-axis machine at its own tolerance (0.3 mm, under the 0.5 mm voxel):
// no cutter fits a slot, so the block is deposited round them. With the tolerance as the
// voxels' band, the voxels at the top corners beside the slots, which a bead rounds by a
// voxel, made the part "NOT manufacturable" over 0.125 mm^3 regions; within a band of a
// voxel they are not a verdict, and the deposit is judged where it matters, on the STL:
// its faces left as deposited stand out beyond 0.3 mm with the head's accuracy.
TEST_F(WholePlan, TheSlotsOnTheBAxisMachineAreJudgedOnTheStlNotRefusedOverCornerVoxels) {
  const Outcome r = run({"plan", kParts + "slots.stl", "--machine", kBAxisMachine, "-o", (dir_ / "plan").string()});
  EXPECT_EQ(r.exit_code, 4) << r.err << r.out;
  EXPECT_EQ(r.out.find("verdict     NOT manufacturable"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("region of the design around (15.8, 0.2, 19.8) mm"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("(exact verification, tolerance 0.3 mm, as deposited)"), std::string::npos) << r.out;
}

// The same tube at the B-axis machine's own tolerance, 0.3 mm, under a voxel: the voxels
// are judged within a band of a voxel (plan/planning_band.hpp), the part against the STL.
//
// Against the STL the roughing's tips on voxel centres used to bite into the tube's round
// wall between the voxel centres they spare, 0.43 mm deep (exact verification found it,
// docs/verification.md; the voxels cannot), and every plan was refused. The flat cutters
// now keep off the STL's real walls and finish them on it (docs/toolpaths.md, "Wall
// finishing"): the block's plan is offered, and what is left off the surface is the last
// cutter's (action 4), 0.013 mm: its finishing passes take the voxels beside the design
// too, which the plan leaves free (they stopped short of them and left 0.249 mm). (Its lowest cut used to sit on a voxel centre
// 0.25 mm above the plate's bottom and leave the block's margin there as a lip; the floor
// is now cut at its real height.)
TEST_F(WholePlan, TheTubeOnAPlateAtTheMachinesToleranceIsMilledFromTheBlockWithItsWallsFinished) {
  const Outcome r = run({"plan", kParts + "tube-plate.stl", "--machine", kBAxisMachine});
  ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
  EXPECT_TRUE(std::regex_search(r.out, std::regex("\n  1\\. \\(+P2 \u2212 "))) << r.out;  // from the block
  EXPECT_EQ(r.out.find("exact_gouge: action 2"), std::string::npos) << r.out;  // the rougher's bite is gone
  EXPECT_NE(r.out.find("exact:     excess 0.013 mm at (20.45, 19.06, 17.25) by action 4 (line "), std::string::npos)
      << r.out;
  // The cutters' levels keep off the STL at their tips and the faces are finished on it
  // (docs/toolpaths.md, "Wall finishing" and "Surface finishing"), not only off the
  // design's voxels: nothing in, where the bull nose's levels bit 0.216 mm.
  EXPECT_TRUE(std::regex_search(r.out, std::regex("\n     exact:     excess [^\n]*, gouge 0\\.00[0-9] mm"))) << r.out;
  EXPECT_EQ(r.out.find("at least"), std::string::npos) << r.out;  // no lip of the margin
}

// The rounded box with its shallow spherical dimple on the B-axis machine at its 0.3 mm:
// the 10 mm bull nose's flat bottom bridges the dimple's bottom (the sphere of 20 mm lies
// 0.4 mm under a flat 8 mm across), so its finishing leaves 0.52 mm there, and validation
// turns down the candidates that reach the dimple with no other tools than that one's
// (docs/validation.md) until the 8 mm ball finishes it on the STL (docs/toolpaths.md,
// "Surface finishing"); the flat cutters finish the rounded edges that side actions left
// staircased.
TEST_F(WholePlan, TheRoundedBoxsDimpleIsFinishedByTheBallOnTheBAxisMachine) {
  const Outcome r = run({"plan", kParts + "rounded-box-dimple.stl", "--machine", kBAxisMachine, "--top", "1"});
  ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
  // From the block, the ball among its removals; the cheaper candidates that reach the
  // dimple with the same tools again are passed over, unexecuted and uncounted.
  EXPECT_TRUE(std::regex_search(r.out, std::regex("\n  1\\. \\(+P2 \u2212 "))) << r.out;
  EXPECT_TRUE(std::regex_search(r.out, std::regex("\n     [0-9]\\) P[0-9]+ +SM-max T3 \\(8 mm ball finisher\\)"))) << r.out;
  EXPECT_TRUE(std::regex_search(r.out, std::regex("[0-9]+ more passed over unexecuted: [^\n]*repeat a failure against the STL")))
      << r.out;
  const std::smatch m = [&] {
    std::smatch found;
    static const std::regex excess(R"(exact:     excess (\d+\.\d+) mm at .*gouge (\d+\.\d+) mm)");
    std::regex_search(r.out, found, excess);
    return found;
  }();
  ASSERT_EQ(m.size(), 3u) << r.out;
  EXPECT_LE(std::stod(m[1]), 0.1) << r.out;
  EXPECT_LE(std::stod(m[2]), 0.1) << r.out;
}

// A block with a closed channel whose pointed roof builds without support: every plan
// offered mills the block up to the channel's floor and deposits only the band above it
// (docs/bands.md), and each one, exported and run on its own simulated controller from the
// raw stock, makes the part within tolerance both ways with no alarm, at the machine's
// own 0.5 mm: the channel's roof stays as deposited, its layers on the roof's sections in
// the middle of the beads' full width (docs/toolpaths.md), and the band deposited is 43 %
// of the part (docs/bands.md).
TEST_F(WholePlan, EveryPlanOfTheArchChannelBlockMillsToTheChannelFloorAndRunsWithinTolerance) {
  const Outcome r = run({"dry-run", std::string(HYBRIDCTL_SOURCE_DIR) + "/examples/parts/arch-channel-block.stl", "--machine",
                         kMachine, "--all", "-o", (dir_ / "dry").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
  EXPECT_NE(r.out.find("dry-run     5 of 5 plans ran to the end with no alarm, within tolerance both ways"), std::string::npos)
      << r.out;
  // The band's milling primitive is in every plan: "P19 ... down to z = 22 mm".
  const std::regex milled("\\n  (P[0-9]+) +SM-max T1 \\(10 mm flat rougher\\) from \\+Z \\(top\\), down to z = 22 mm");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(r.out, m, milled)) << r.out;
  const std::string band = m[1];
  std::size_t plans = 0;
  const std::regex plan_line("\nplan [0-9]+ +(\\(.*)  cost");
  for (std::sregex_iterator it(r.out.begin(), r.out.end(), plan_line), end; it != end; ++it, ++plans)
    EXPECT_NE((*it)[1].str().find(band + ")"), std::string::npos) << (*it)[1];
  EXPECT_EQ(plans, 5u) << r.out;
  // No plan deposits more than half the part (92,817 mm^3): the deposits are the band.
  const std::regex deposit(R"(\n +[0-9]+\) P[0-9]+ +[UO]-AM [^\n]* deposit +([0-9.]+) mm)");
  std::size_t deposits = 0;
  for (std::sregex_iterator it(r.out.begin(), r.out.end(), deposit), end; it != end; ++it, ++deposits)
    EXPECT_LE(std::stod((*it)[1]), 92817.0 / 2) << (*it)[0];
  EXPECT_GE(deposits, 5u) << r.out;
}

// dry-run plans as `plan` does, with its tolerance and reuse: the tolerance asked for is
// the one planned with and the one the part as built is judged against.
TEST_F(WholePlan, DryRunPlansAndJudgesWithTheToleranceAskedFor) {
  const std::string fins = std::string(HYBRIDCTL_SOURCE_DIR) + "/examples/parts/fins.stl";
  const Outcome r = run({"dry-run", fins, "--machine", kMachine, "--tolerance", "0.75", "--reuse", "2", "-o",
                         (dir_ / "dry").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
  EXPECT_NE(r.out.find("), tolerance 0.75 mm\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("within the planning band (0.75 mm)"), std::string::npos) << r.out;  // the voxels
  EXPECT_NE(r.out.find("% of the surface within 0.75 mm: within tolerance\nwrote"), std::string::npos) << r.out;  // the STL
  const std::string json = slurp(dir_ / "dry" / "plan" / "plan.json");
  EXPECT_NE(json.find("\"max_uses\": 2"), std::string::npos);
  EXPECT_NE(json.find("\"tolerance\": 0.75"), std::string::npos);
  EXPECT_EQ(run({"dry-run", fins, "--machine", kMachine, "--tolerance", "-1"}).exit_code, 2);
  EXPECT_EQ(run({"dry-run", fins, "--machine", kMachine, "--reuse", "0"}).exit_code, 2);
}

// The titanium boss plate on the wire-DED machine at its own 0.5 mm: a boss 40 mm across
// and 60 tall on a 12 mm plate is deposited on a plate of the base's thickness and milled to
// size, and that costs less than milling it from the 72 mm block (docs/costs.md). Its
// hybrid plans used to fail exact verification "at least 1.479 mm" out on the plate's face
// round the boss, which the cutter had faced: a bead that only touched the face's vectors
// at their end left a run of no length there that no cut took away.
TEST_F(WholePlan, TheBossPlateIsDepositedAndMilledForLessThanMillingItFromTheBlock) {
  const Outcome r = run({"plan", kParts + "boss-plate.stl", "--machine",
                         std::string(HYBRIDCTL_SOURCE_DIR) + "/examples/machines/wire-ded-ti.yaml", "--top", "2", "--compare"});
  ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
  EXPECT_NE(r.out.find("objective   money"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("at least"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("compare     each way of making the part"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("hybrid             from plate-12 (plate), 1 deposit, "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("milled from stock  from block (box), 2 removals"), std::string::npos) << r.out;
  const std::size_t saves = r.out.find("the hybrid plan costs ");
  ASSERT_NE(saves, std::string::npos) << r.out;
  const double percent = std::stod(r.out.substr(saves + 22));
  EXPECT_GE(percent, 25) << r.out.substr(saves, 100);
  EXPECT_NE(r.out.find("% less than the best plan milled from stock"), std::string::npos) << r.out;
}

// A repair (issue 16): the worn copy of the flanged hub (2.5 mm gone from half of the
// flange's top) given as the stock. Every plan starts from it and deposits only what it
// lacks; the best lays the missing region near-net and leaves it as deposited, others
// overfill it and mill it back, and every plan offered, run from the worn part on its own
// simulated controller, makes the hub within tolerance both ways with no alarm.
TEST_F(WholePlan, AWornHubIsRepairedByDepositingOnlyWhatItLacksAndEveryPlanRunsWithinTolerance) {
  const std::string source = HYBRIDCTL_SOURCE_DIR;
  // At 0.7 mm: the repaired faces stay as deposited, within the powder head's 0.25 mm of
  // the modelled beads, which 0.5 mm does not allow (docs/verification.md).
  const Outcome r = run({"dry-run", kFlangedHub, "--machine", kMachine, "--voxel", "0.5", "--tolerance", "0.7", "--stock",
                         source + "/examples/parts/flanged-hub-worn.stl", "--all", "-o", (dir_ / "dry").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
  std::smatch ran;
  ASSERT_TRUE(std::regex_search(r.out, ran, std::regex("dry-run     ([0-9]+) of \\1 plans ran to the end with no alarm, "
                                                       "within tolerance both ways")))
      << r.out;
  EXPECT_GE(std::stoi(ran[1]), 3);
  // "  1. (P1 ∪ P2)": the stock and a near-net deposit from the top, which lays only what
  // the stock lacks (the whole design's U-AM or the one near the missing region).
  std::smatch best;
  ASSERT_TRUE(std::regex_search(r.out, best, std::regex("\\n  1\\. \\(P1 ∪ (P[0-9]+)\\)  cost"))) << r.out;
  EXPECT_TRUE(std::regex_search(r.out, std::regex("\\n  " + std::string(best[1]) + " +U-AM ded from \\+Z \\(top\\)")))
      << r.out;
  // The repair shops plan by hand: overfill near the missing region, then mill it back.
  // Its beads stand past the flange's rim under the voxels the removal meets; the rim is
  // finished down to them (docs/toolpaths.md, "Wall finishing").
  std::smatch overfill;
  ASSERT_TRUE(std::regex_search(r.out, overfill, std::regex("\\n  (P[0-9]+) +O-AM ded from \\+Z \\(top\\), near the missing 2454 mm")))
      << r.out;
  EXPECT_TRUE(std::regex_search(r.out, std::regex("\\n  [0-9]\\. \\(\\(P1 ∪ " + std::string(overfill[1]) + "\\) − P[0-9]+\\)  cost")))
      << r.out;
  // Every action after the stock deposits at most the missing 2,454 mm³ and its overfill.
  const std::regex deposit("\\n     [0-9]\\) P[0-9]+ +[UO]-AM [^\\n]* deposit +([0-9.]+) mm");
  int deposits = 0;
  for (auto it = std::sregex_iterator(r.out.begin(), r.out.end(), deposit); it != std::sregex_iterator(); ++it, ++deposits)
    EXPECT_LT(std::stod((*it)[1]), 2454 * 1.4) << it->str();
  EXPECT_GE(deposits, 2);
}

// hybridctl export as a user runs it, on the bundled example parts that have valid plans on
// the LinuxCNC machine: every program of their two best plans is exported, and LinuxCNC's
// own interpreter (rs274, the real peer unpacked by scripts/setup) and `hybridctl gcode
// check` accept it.
TEST_F(WholePlan, EveryProgramForTheExamplePartsPassesRs274AndOurCheck) {
  ASSERT_TRUE(fs::exists(fs::path(HYBRIDCTL_SOURCE_DIR) / ".peers/linuxcnc/usr/bin/rs274"))
      << "LinuxCNC's rs274 is missing: run scripts/setup (it unpacks linuxcnc-uspace into .peers/linuxcnc)";
  const fs::path rs274 = fs::path(HYBRIDCTL_SOURCE_DIR) / "scripts/rs274";
  for (const std::string part : {"flanged-hub", "fins", "overhang"}) {
    const fs::path plan = dir_ / part / "plan";
    const Outcome planned =
        run({"plan", kParts + part + ".stl", "--machine", kMachine, "--voxel", "0.5", "--top", "2", "-o", plan.string()});
    ASSERT_EQ(planned.exit_code, 0) << part << "\n" << planned.out << planned.err;
    int programs = 0;
    for (int rank = 1; rank <= 2; ++rank) {
      const fs::path out = dir_ / part / ("plan-" + std::to_string(rank));
      const Outcome exported = run({"export", plan.string(), "--plan", std::to_string(rank), "-o", out.string()});
      ASSERT_EQ(exported.exit_code, 0) << part << " plan " << rank << "\n" << exported.out << exported.err;
      for (const auto& entry : fs::directory_iterator(out)) {
        if (entry.path().extension() != ".ngc") continue;
        ++programs;
        const Outcome linuxcnc =
            run_shell(quote(rs274.string()) + " -t " + quote((out / "tool.tbl").string()) + " -g " + quote(entry.path().string()), dir_);
        EXPECT_EQ(linuxcnc.exit_code, 0) << entry.path() << "\n" << linuxcnc.err.substr(0, 2000);
        const Outcome ours = run({"gcode", "check", entry.path().string(), "--machine", kMachine});
        EXPECT_EQ(ours.exit_code, 0) << entry.path() << "\n" << ours.out.substr(0, 2000) << ours.err;
      }
    }
    EXPECT_GE(programs, 2 * 2) << part << ": a whole program and at least one action program per plan";
  }
}

}  // namespace
