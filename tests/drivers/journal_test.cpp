// The job journal (drivers/journal.hpp): what a run writes is what a resume reads back,
// whatever the background sync was doing when the journal was moved or closed; one job per
// directory; a torn last line is a crash, anything else malformed is named by file and line.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "common/error.hpp"
#include "drivers/journal.hpp"

namespace hybridctl::drivers {
namespace {

namespace fs = std::filesystem;

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("hybridctl-journal-" + name + "-" + std::to_string(::getpid()));
  fs::remove_all(d);
  return d;
}

JournalHeader header() {
  JournalHeader h;
  h.program = "/jobs/part.ngc";
  h.identity = 0x0123456789abcdefULL;
  h.lines = 5000;
  h.machine = "machine.yaml";
  h.transport = "modbus-tcp://127.0.0.1:1502";
  h.source = "plan.json rank 1";
  return h;
}

TEST(Journal, ReadsBackTheHeaderAndTheLastAcknowledgedRange) {
  const fs::path dir = fresh_dir("read-back");
  {
    Journal j = Journal::create(dir, header());
    j.sync_period_s = 0;  // a background sync for every range
    for (std::uint32_t chunk = 1; chunk <= 200; ++chunk) j.acknowledged(chunk, chunk * 20, chunk * 20 - 40);
    // Moved while syncs may be in flight: the new owner keeps writing the same file.
    Journal moved = std::move(j);
    moved.note("controller restarted");
    moved.acknowledged(201, 4020, 4000);
  }
  const Journal back = Journal::open(dir);
  EXPECT_EQ(back.header().program, "/jobs/part.ngc");
  EXPECT_EQ(back.header().identity, 0x0123456789abcdefULL);
  EXPECT_EQ(back.header().lines, 5000u);
  EXPECT_EQ(back.header().transport, "modbus-tcp://127.0.0.1:1502");
  EXPECT_EQ(back.progress().last_chunk, 201u);
  EXPECT_EQ(back.progress().through_line, 4020u);
  EXPECT_EQ(back.progress().executed_line, 4000u);
  EXPECT_FALSE(back.progress().completed);
  fs::remove_all(dir);
}

TEST(Journal, RecordsTheEndOfTheJob) {
  const fs::path dir = fresh_dir("completed");
  {
    Journal j = Journal::create(dir, header());
    j.acknowledged(1, 5000, 0);
    j.completed(5000);
  }
  const Journal back = Journal::open(dir);
  EXPECT_TRUE(back.progress().completed);
  EXPECT_EQ(back.progress().executed_line, 5000u);
  fs::remove_all(dir);
}

TEST(Journal, ADirectoryHoldsOneJob) {
  const fs::path dir = fresh_dir("one-job");
  { Journal j = Journal::create(dir, header()); }
  try {
    Journal::create(dir, header());
    FAIL() << "a second journal was started in the same directory";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--resume"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

TEST(Journal, ATornLastLineIsACrashAMalformedLineElsewhereIsAnError) {
  const fs::path dir = fresh_dir("torn");
  {
    Journal j = Journal::create(dir, header());
    j.acknowledged(1, 100, 0);
    j.acknowledged(2, 200, 50);
  }
  const fs::path file = dir / "journal.jsonl";
  { std::ofstream(file, std::ios::app) << "{\"chunk\": 3, \"through_li"; }
  EXPECT_EQ(Journal::open(dir).progress().last_chunk, 2u) << "the torn write is ignored";

  { std::ofstream(file, std::ios::app) << "\n{\"chunk\": 4, \"through_line\": 400, \"executed_line\": 300}\n"; }
  try {
    Journal::open(dir);
    FAIL() << "a malformed line before the last was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("journal.jsonl:4:"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace hybridctl::drivers
