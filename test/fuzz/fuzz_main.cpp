// A libFuzzer harness of one configuration loader (test/fuzz/fuzz_targets.h); DM_FUZZ_TARGET names
// it. Built by scripts/sanitize.sh with clang (-fsanitize=fuzzer,address,undefined); run there for
// a fixed number of inputs, or longer on demand: scripts/fuzz.sh TARGET SECONDS.
#include <cstddef>
#include <cstdint>

#include "fuzz_targets.h"

#ifndef DM_FUZZ_TARGET
#error "DM_FUZZ_TARGET must name the target"
#endif

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const dem_mobility::fuzz::Target& target = dem_mobility::fuzz::FindTarget(DM_FUZZ_TARGET);
  target.Run(data, size);
  return 0;
}
