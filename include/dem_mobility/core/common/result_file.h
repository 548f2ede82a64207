// The one result file every scene writes: a YAML map that opens with the same keys for every kind
// (scene, kind, status, error) and goes on with the scene's own figures, in the order they are set.
// Doubles are written with 17 significant digits (they read back exactly).
#pragma once

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "dem_mobility/core/common/energy.h"
#include "dem_mobility/core/common/error.h"

namespace dem_mobility::core {

class ResultFile {
 public:
  /// `scene_file`: the scene that ran; `kind`: its `scene:` key (road_slope, cone_penetrometer, ...).
  ResultFile(const std::string& scene_file, const std::string& kind);

  /// Status (ok, error, interrupted, or a scene's own verdict such as steady or no_go) and error
  /// text (empty on success); both may be set at any time, they stay at the top of the file.
  void SetStatus(const std::string& status, const std::string& error = "");
  const std::string& status() const { return status_; }
  const std::string& error() const { return error_; }

  /// A figure; the schema's own keys (scene, kind, status, error) are set by the constructor and
  /// SetStatus only.
  template <class T>
  ResultFile& Set(const std::string& key, const T& value) {
    DM_DEMAND(!Reserved(key));
    body_[key] = value;
    return *this;
  }
  /// A figure that may not have been measured: written as null when not finite (a result never
  /// holds NaN).
  ResultFile& SetMeasured(const std::string& key, double value) {
    if (std::isfinite(value)) return Set(key, value);
    return Set(key, YAML::Node());
  }
  /// A list written on one line ([a, b, c]).
  ResultFile& SetFlow(const std::string& key, const std::vector<double>& values);
  /// A map of counts (e.g. messages published by topic).
  ResultFile& SetCounts(const std::string& key, const std::vector<std::pair<std::string, long>>& counts);
  /// A ledger followed along a run (LedgerWatch): PREFIX_dissipated, _dissipated_least,
  /// _dissipated_least_time, _largest_fall, _scale, _samples.
  ResultFile& SetLedger(const std::string& prefix, const LedgerWatch& w);
  /// A map of equally long columns, each on one line (a history: t, x, speed, ...).
  ResultFile& SetColumns(const std::string& key, const std::vector<std::pair<std::string, std::vector<double>>>& cols);

  std::string Text() const;
  /// Writes the file; ConfigError naming the path when it cannot.
  void Write(const std::string& path) const;
  /// Makes the parent folder and checks that `path` can be written, before a run spends time on
  /// its results. ConfigError naming the path (and `what`, e.g. a parameter name) when it cannot.
  static void CheckWritable(const std::string& path, const std::string& what = "");

 private:
  static bool Reserved(const std::string& key);
  std::string scene_, kind_, status_ = "ok", error_;
  YAML::Node body_;
};

}  // namespace dem_mobility::core
