// Morphology at 128^3, 256^3 and 512^3: dilation by a ball of radius 10 voxels and by a
// flat end mill with shank and holder, each by the exact fast path and, as the
// baseline in the same run, by FFT convolution (the paper's method). Report ratios.

#include <benchmark/benchmark.h>

#include <map>

#include "bench/bench_main.hpp"

#include "geometry/morphology.hpp"
#include "geometry/shapes.hpp"

namespace {

using namespace hybridctl::geometry;

// A part-like solid filling most of an n^3 grid: a block with a through hole and a
// boss, so the element meets flat faces, edges and curved surfaces.
const Solid& workpiece(int n) {
  static std::map<int, Solid> cache;
  auto it = cache.find(n);
  if (it != cache.end()) return it->second;
  const Lattice l{1.0, {0, 0, 0}};
  const double m = 12, s = n - 2 * m;  // leave room for the element
  Solid part = make_box(l, {{m, m, m}, {m + s, m + s, m + 0.6 * s}});
  part = subtract(part, make_cylinder(l, Axis::Z, {m + 0.3 * s, m + 0.5 * s, 0}, 0.12 * s, n));
  part = unite(part, make_cylinder(l, Axis::Z, {m + 0.7 * s, m + 0.5 * s, m}, 0.15 * s, 0.95 * s));
  return cache.emplace(n, std::move(part)).first->second;
}

AxialBody flat_mill() {
  // 10 voxel radius cutter over 20, a 6 voxel shank over 20 more, a 14 voxel holder.
  return {{Axis::Z, +1},
          {{AxialSection::Kind::Cylinder, 0, 20, 10, 0, 0},
           {AxialSection::Kind::Cylinder, 20, 40, 6, 0, 0},
           {AxialSection::Kind::Cylinder, 40, 50, 14, 0, 0}}};
}

void run(benchmark::State& state, const StructuringElement& element, MorphologyMethod method) {
  const int n = int(state.range(0));
  const Solid& part = workpiece(n);
  const IndexBox domain{{0, 0, 0}, {n, n, n}};
  std::int64_t voxels = 0;
  for (auto _ : state) {
    const Solid d = dilate(part, element, domain, method);
    voxels = d.voxel_count();
    benchmark::DoNotOptimize(voxels);
  }
  state.counters["grid"] = n;
  state.counters["result_voxels"] = double(voxels);
}

void BM_Ball_Fast(benchmark::State& s) { run(s, Ball{10}, MorphologyMethod::Auto); }
void BM_Ball_Fft(benchmark::State& s) { run(s, Ball{10}, MorphologyMethod::Fft); }
void BM_FlatMill_Fast(benchmark::State& s) { run(s, flat_mill(), MorphologyMethod::Auto); }
void BM_FlatMill_Fft(benchmark::State& s) { run(s, flat_mill(), MorphologyMethod::Fft); }

BENCHMARK(BM_Ball_Fast)->Arg(128)->Arg(256)->Arg(512)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Ball_Fft)->Arg(128)->Arg(256)->Arg(512)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_FlatMill_Fast)->Arg(128)->Arg(256)->Arg(512)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_FlatMill_Fft)->Arg(128)->Arg(256)->Arg(512)->Unit(benchmark::kMillisecond)->UseRealTime();

// --smoke: each element and method at 64^3, once.
void register_smoke_cases() {
  for (auto [name, fn] : {hybridctl::bench::NamedCase{"BM_Ball_Fast", BM_Ball_Fast}, hybridctl::bench::NamedCase{"BM_Ball_Fft", BM_Ball_Fft},
                          hybridctl::bench::NamedCase{"BM_FlatMill_Fast", BM_FlatMill_Fast}, hybridctl::bench::NamedCase{"BM_FlatMill_Fft", BM_FlatMill_Fft}})
    hybridctl::bench::smoke_case(name, fn)->Arg(64)->Unit(benchmark::kMillisecond);
}

}  // namespace

int main(int argc, char** argv) { return hybridctl::bench::run_benchmarks(argc, argv, register_smoke_cases); }
