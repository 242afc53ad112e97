// The simulator's fault schedule (sim/wire/fault_injection.hpp): periodic by default, random
// from a seed for soak runs, and the same faults every time for the same seed.

#include <gtest/gtest.h>

#include <vector>

#include "sim/wire/fault_injection.hpp"

namespace hybridctl::sim::wire {
namespace {

std::vector<bool> drops(FaultInjector& f, int events) {
  std::vector<bool> out;
  for (int i = 0; i < events; ++i) out.push_back(f.drop_request());
  return out;
}

TEST(FaultInjector, WithoutASeedEveryNthEventIsHit) {
  FaultOptions o;
  o.drop_every = 5;
  FaultInjector f(o);
  const auto d = drops(f, 20);
  for (int i = 0; i < 20; ++i) EXPECT_EQ(d[i], (i + 1) % 5 == 0) << "event " << i + 1;
  EXPECT_EQ(f.counters().dropped, 4u);
}

TEST(FaultInjector, WithASeedEventsAreHitAtRandomAtTheSameMeanRate) {
  FaultOptions o;
  o.drop_every = 25;
  o.seed = 7;
  FaultInjector f(o);
  const auto d = drops(f, 100000);
  // 4,000 expected; the binomial standard deviation is ~62.
  EXPECT_GT(f.counters().dropped, 3700u);
  EXPECT_LT(f.counters().dropped, 4300u);
  // Not every 25th: some gaps are shorter, some longer.
  int last = -1, shortest = 1 << 30, longest = 0;
  for (int i = 0; i < int(d.size()); ++i) {
    if (!d[i]) continue;
    if (last >= 0) {
      shortest = std::min(shortest, i - last);
      longest = std::max(longest, i - last);
    }
    last = i;
  }
  EXPECT_LT(shortest, 25);
  EXPECT_GT(longest, 25);
}

TEST(FaultInjector, TheSameSeedGivesTheSameFaults) {
  FaultOptions o;
  o.drop_every = 10;
  o.corrupt_every = 7;
  o.delay_ms = 20;
  o.seed = 42;
  FaultInjector a(o), b(o);
  for (int i = 0; i < 1000; ++i) {
    ASSERT_EQ(a.drop_request(), b.drop_request());
    ASSERT_EQ(a.corrupt_reply(), b.corrupt_reply());
    ASSERT_EQ(a.reply_delay(), b.reply_delay());
  }
  FaultOptions other = o;
  other.seed = 43;
  FaultInjector c(o), d(other);
  EXPECT_NE(drops(c, 1000), drops(d, 1000)) << "another seed, other faults";
}

TEST(FaultInjector, RandomDelaysSpanZeroToTheLimit) {
  FaultOptions o;
  o.delay_ms = 10;
  o.seed = 1;
  FaultInjector f(o);
  std::vector<int> seen(11, 0);
  for (int i = 0; i < 2000; ++i) {
    const auto ms = f.reply_delay().count();
    ASSERT_GE(ms, 0);
    ASSERT_LE(ms, 10);
    ++seen[static_cast<std::size_t>(ms)];
  }
  for (int ms = 0; ms <= 10; ++ms) EXPECT_GT(seen[static_cast<std::size_t>(ms)], 0) << ms << " ms never drawn";
  EXPECT_EQ(f.counters().delayed, 2000u - static_cast<std::uint64_t>(seen[0])) << "a zero delay is no delay";
}

}  // namespace
}  // namespace hybridctl::sim::wire
