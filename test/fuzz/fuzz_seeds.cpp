// Writes the fuzz targets' seeds (the shipped configuration files, test/fuzz/fuzz_targets.h) into
// DIR/<target>/seed_<n>: the corpus scripts/sanitize.sh starts the fuzzers from.
//   fuzz_seeds DIR
#include <filesystem>
#include <fstream>
#include <iostream>

#include "fuzz_targets.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: fuzz_seeds DIR\n";
    return 2;
  }
  for (const auto& t : dem_mobility::fuzz::Targets()) {
    const std::filesystem::path dir = std::filesystem::path(argv[1]) / t.name;
    std::filesystem::create_directories(dir);
    const auto seeds = t.seeds();
    for (size_t i = 0; i < seeds.size(); ++i) std::ofstream(dir / ("seed_" + std::to_string(i)), std::ios::binary) << seeds[i];
    std::cout << t.name << ": " << seeds.size() << " seeds\n";
  }
  return 0;
}
