// The configuration loaders as fuzz targets (issue 16): each takes an arbitrary text in place of
// one configuration file and reads and checks it as a run would before it starts (nothing runs, no
// soil is prepared). Bad input must end in a ConfigError naming the file and key: the targets
// swallow that and nothing else, so any other exception, a crash or a sanitizer report is a
// finding. The libFuzzer harnesses (fuzz_main.cpp, one program per target) and the regression test
// over test/fuzz/regressions (config_test) call the same functions.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace dem_mobility::fuzz {

struct Target {
  std::string name;  ///< fuzz_<name>, test/fuzz/regressions/<name>/
  std::string what;
  /// Reads and checks `data` as the target's file (a ConfigError for bad input).
  void (*read)(const std::string& data);
  /// The shipped files of the target's kind, as its inputs: the fuzzers' seeds.
  std::vector<std::string> (*seeds)();
  /// read(), with a ConfigError the answer to bad input: returns normally for that too. Anything
  /// else (another exception, a crash, a sanitizer report) is a finding.
  void Run(const std::uint8_t* data, std::size_t size) const;
};

/// scene, vehicle, terrain, soil, calibration.
const std::vector<Target>& Targets();
const Target& FindTarget(const std::string& name);

/// The vehicle target's input: its first byte picks the file of the shipped vehicle it stands in
/// for (the top file, then the files it names, in VehicleFiles()' order), the rest is the text.
const std::vector<std::string>& VehicleFiles();

}  // namespace dem_mobility::fuzz
