#pragma once
// What every fuzz target shares: an invariant check that libFuzzer sees as a crash.
//
// The targets call the code under test with arbitrary input and catch only the exception
// its header documents (hybridctl::InputError and its kind); anything else escapes and
// aborts, as does a failed FUZZ_CHECK. Each abort is a finding: the input is saved as
// crash-<sha1> and reproduces with `build-fuzz/fuzz/<name>_fuzz crash-<sha1>`.

#include <cstdio>
#include <cstdlib>

#define FUZZ_CHECK(condition, what)                                                         \
  do {                                                                                      \
    if (!(condition)) {                                                                     \
      std::fprintf(stderr, "%s:%d: invariant broken: %s (%s)\n", __FILE__, __LINE__, what, \
                   #condition);                                                             \
      std::abort();                                                                         \
    }                                                                                       \
  } while (0)
