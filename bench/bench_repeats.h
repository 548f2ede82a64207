// What the benchmarks share: how many times each rate is timed (the best of them is printed).
#pragma once

#include <cstdio>
#include <cstdlib>

namespace dem_mobility::bench {

/// DM_BENCH_REPEATS (default 3): a whole number from 1 to 100; anything else ends the program with
/// exit code 2, naming the variable and `program`.
inline int Repeats(const char* program) {
  const char* e = std::getenv("DM_BENCH_REPEATS");
  if (!e) return 3;
  char* end = nullptr;
  const long r = std::strtol(e, &end, 10);
  if (end == e || *end != '\0' || r < 1 || r > 100) {
    std::fprintf(stderr, "%s: DM_BENCH_REPEATS=%s must be a whole number from 1 to 100\n", program, e);
    std::exit(2);
  }
  return static_cast<int>(r);
}

}  // namespace dem_mobility::bench
