// G-code language throughput on a synthetic ~100k-line milling program for the
// hybrid-3axis example machine (zigzag rows of G1 moves with a G2/G3 turn between rows):
//   parser       lines/s of Parser::parse_line into one reused Block (the program's lines,
//                and 100k longer `N.. G1 X.. Y.. Z.. F..` lines)
//   interpreter  lines/s of Interpreter::execute_line (parse + modal execution)
//   check        lines/s of check_program (interpretation, envelope, time estimate)
//   writer       lines/s of write_program (generation + its interpreter/envelope self-check)
// Single-threaded. Run: build/bench/gcode_bench

#include <benchmark/benchmark.h>

#include <cstdio>
#include <string>
#include <vector>

#include "bench/bench_main.hpp"

#include "config/machine_loader.hpp"
#include "gcode/check.hpp"
#include "gcode/interpreter.hpp"
#include "gcode/parser.hpp"
#include "gcode/post.hpp"

namespace {

using namespace hybridctl;
using namespace hybridctl::gcode;

const config::Machine& machine() {
  static const config::Machine m =
      config::load_machine(std::string(HYBRIDCTL_SOURCE_DIR) + "/examples/machines/hybrid-3axis.yaml");
  return m;
}

/// Rows 0.1 mm apart across 100 mm, 10 segments a row, a half circle between rows.
std::vector<ActionProgram> synthetic_actions(int target_moves) {
  ActionProgram a;
  a.action = 1;
  a.primitive = "P1";
  a.label = "benchmark zigzag";
  a.additive = false;
  a.path.process = Process::Milling;
  a.path.tool_number = 1;
  a.path.setup = "top";
  a.path.start = {-50, -50, 20};
  a.path.safe_z = 20;
  auto& moves = a.path.moves;
  moves.push_back({MoveKind::Rapid, {-50, -50, 5}, {}, 0, false, ""});
  moves.push_back({MoveKind::Feed, {-50, -50, 1}, {}, 300, false, ""});
  double y = -50;
  int row = 0;
  const double step = 100.0 / 1000;  // keeps y within +-50 mm for 1000 rows
  while (static_cast<int>(moves.size()) < target_moves) {
    const bool forward = row % 2 == 0;
    for (int k = 1; k <= 10; ++k) {
      const double x = forward ? -50 + 10.0 * k : 50 - 10.0 * k;
      moves.push_back({MoveKind::Feed, {x, y, 1}, {}, 1200.0 + (k % 2) * 10, true, ""});
    }
    const double x_end = forward ? 50 : -50;
    const double next_y = y + step;
    const MoveKind turn = forward ? MoveKind::ArcCcw : MoveKind::ArcCw;
    moves.push_back({turn, {x_end, next_y, 1}, {x_end, y + step / 2, 0}, 1200, true, ""});
    y = next_y;
    if (y > 49) y = -50;
    ++row;
  }
  moves.push_back({MoveKind::Rapid, {moves.back().to.x, moves.back().to.y, 20}, {}, 0, false, ""});
  return {a};
}

// The program's moves: 100k, 2,000 for --smoke.
int g_moves = 100000;

const std::string& program_text() {
  static const std::string text = write_program(synthetic_actions(g_moves), machine());
  return text;
}

std::vector<std::string_view> program_lines() {
  std::vector<std::string_view> lines;
  for_each_line(program_text(), [&](std::string_view l, int) { lines.push_back(l); });
  return lines;
}

void BM_Parser(benchmark::State& state) {
  const auto lines = program_lines();
  const Parser parser("bench.ngc");
  Block block;
  for (auto _ : state) {
    int n = 0;
    for (auto l : lines) parser.parse_line(l, ++n, block);
    benchmark::DoNotOptimize(block);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(lines.size()));
  state.counters["lines"] = static_cast<double>(lines.size());
}
BENCHMARK(BM_Parser)->Unit(benchmark::kMillisecond);

/// Longer lines: every axis, four decimals, a feed and a comment on every tenth line.
void BM_ParserFullLines(benchmark::State& state) {
  std::vector<std::string> lines;
  for (int i = 0; i < g_moves; ++i) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "N%d G1 X%.4f Y%.4f Z%.4f F%d%s", i, (i % 997) * 0.1234, -(i % 313) * 0.5678,
                  (i % 7) * 0.25, 1000 + i % 50, i % 10 == 0 ? " (row)" : "");
    lines.emplace_back(buf);
  }
  const Parser parser("bench.ngc");
  Block block;
  for (auto _ : state) {
    int n = 0;
    for (const auto& l : lines) parser.parse_line(l, ++n, block);
    benchmark::DoNotOptimize(block);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(lines.size()));
}
BENCHMARK(BM_ParserFullLines)->Unit(benchmark::kMillisecond);

void BM_Interpreter(benchmark::State& state) {
  const auto lines = program_lines();
  std::size_t motions = 0;
  for (auto _ : state) {
    Interpreter in(machine(), "bench.ngc");
    int n = 0;
    motions = 0;
    for (auto l : lines) motions += in.execute_line(l, ++n).motions.size();
    benchmark::DoNotOptimize(motions);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(lines.size()));
  state.counters["motions"] = static_cast<double>(motions);
}
BENCHMARK(BM_Interpreter)->Unit(benchmark::kMillisecond);

void BM_Check(benchmark::State& state) {
  const std::string& text = program_text();
  int lines = 0;
  for (auto _ : state) {
    const CheckReport r = check_program(text, machine(), "bench.ngc");
    lines = r.lines;
    if (!r.clean()) state.SkipWithError("the synthetic program is not clean");
  }
  state.SetItemsProcessed(state.iterations() * lines);
}
BENCHMARK(BM_Check)->Unit(benchmark::kMillisecond);

void BM_Writer(benchmark::State& state) {
  const auto actions = synthetic_actions(g_moves);
  std::size_t lines = 0;
  for (auto _ : state) {
    const std::string text = write_program(actions, machine());
    lines = 0;
    for (char c : text) lines += c == '\n';
    benchmark::DoNotOptimize(text.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(lines));
  state.counters["lines"] = static_cast<double>(lines);
}
BENCHMARK(BM_Writer)->Unit(benchmark::kMillisecond);

}  // namespace


namespace {

// --smoke: every case once, on a program of 2,000 moves.
void register_smoke_cases() {
  g_moves = 2000;
  for (auto [name, fn] : {hybridctl::bench::NamedCase{"BM_Parser", BM_Parser}, hybridctl::bench::NamedCase{"BM_ParserFullLines", BM_ParserFullLines},
                          hybridctl::bench::NamedCase{"BM_Interpreter", BM_Interpreter}, hybridctl::bench::NamedCase{"BM_Check", BM_Check},
                          hybridctl::bench::NamedCase{"BM_Writer", BM_Writer}})
    hybridctl::bench::smoke_case(name, fn)->Unit(benchmark::kMillisecond);
}

}  // namespace

int main(int argc, char** argv) { return hybridctl::bench::run_benchmarks(argc, argv, register_smoke_cases); }
