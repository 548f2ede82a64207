// A strict YAML reader: every error names the file, the key path and the value, and keys that
// nobody reads are reported as unknown.
#pragma once

#include <Eigen/Core>
#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "dem_mobility/core/common/error.h"
#include "dem_mobility/core/common/table.h"

namespace dem_mobility::core {

/// One map (or sequence element) of a YAML document, with the file it came from and its key path.
///
/// Reading a key marks it as used; Finish() throws for every key that was never read, so a typo in
/// a configuration file is an error instead of a silently ignored setting.
class YamlReader {
 public:
  /// The largest configuration file Load reads (the shipped ones are under 20 kB).
  static constexpr std::uintmax_t kMaxFileBytes = 16u << 20;
  /// Loads `path`; throws ConfigError naming the file when it is missing, not a regular file,
  /// larger than kMaxFileBytes or malformed.
  static YamlReader Load(const std::string& path);
  /// Loads `path` and applies `key=value` overrides (dotted keys for nested maps: driver.kp=4000);
  /// a value is parsed as YAML. An override of a key (or map) the file lacks is added, so the
  /// reader then rejects it if it is unknown.
  static YamlReader LoadWithOverrides(const std::string& path, const std::vector<std::string>& overrides);
  /// Parses text (for tests); `name` stands in for the file name in messages.
  static YamlReader FromString(const std::string& text, const std::string& name = "<string>");

  YamlReader(YAML::Node node, std::string file, std::string path);

  bool Has(const std::string& key) const;
  /// Whether `key` of this map was set by an override of LoadWithOverrides (not marked as read).
  bool Overridden(const std::string& key) const;
  double Double(const std::string& key) const;
  double Double(const std::string& key, double fallback) const;
  /// A double that must lie in [lo, hi].
  double DoubleIn(const std::string& key, double lo, double hi) const;
  double DoubleIn(const std::string& key, double lo, double hi, double fallback) const;
  double Positive(const std::string& key) const;
  double Positive(const std::string& key, double fallback) const;
  double NonNegative(const std::string& key) const;
  double NonNegative(const std::string& key, double fallback) const;
  int Int(const std::string& key) const;
  int Int(const std::string& key, int fallback) const;
  bool Bool(const std::string& key, bool fallback) const;
  std::string String(const std::string& key) const;
  std::string String(const std::string& key, const std::string& fallback) const;
  Eigen::Vector3d Vector3(const std::string& key) const;
  Eigen::Vector3d Vector3(const std::string& key, const Eigen::Vector3d& fallback) const;
  std::vector<double> DoubleList(const std::string& key) const;
  /// A piecewise-linear table given as a list of [x, y] pairs with strictly increasing x.
  Table1D Table(const std::string& key) const;

  YamlReader Child(const std::string& key) const;
  /// Whether `key` is there and holds a map, or a list (not marked as read).
  bool IsMap(const std::string& key) const;
  bool IsList(const std::string& key) const;
  /// The value of `key` written as flow YAML (a list: "[0.3, 0.7]").
  std::string FlowText(const std::string& key) const;
  /// The keys of this map, in the file's order (not marked as read).
  std::vector<std::string> Keys() const;
  /// This map as YAML text, overrides applied (what a cache keys on; marks nothing as read).
  std::string Dump() const;

  /// Resolves a path written in this file relative to the file's folder.
  std::string ResolvePath(const std::string& relative) const;
  /// Throws ConfigError listing every key of this map (not recursing) that was never read.
  void Finish() const;

  const std::string& file() const { return file_; }
  const std::string& path() const { return path_; }
  /// "file: key.path" for messages.
  std::string Where(const std::string& key) const;
  [[noreturn]] void Fail(const std::string& key, const std::string& message) const;

 private:
  YAML::Node Get(const std::string& key) const;
  /// A key of this map as text; ConfigError for a key that is a list or a map.
  std::string KeyText(const YAML::Node& key) const;
  template <typename T>
  T As(const std::string& key, const YAML::Node& n, const char* what) const;

  YAML::Node node_;
  std::string file_;
  std::string path_;
  std::shared_ptr<std::set<std::string>> used_;
  /// the dotted key paths the overrides set (shared by the document's readers)
  std::shared_ptr<std::set<std::string>> overridden_;
};

/// Opens a configuration file by its path: YamlReader::Load, or (the fuzz harnesses) text given in
/// place of one of the files a loader chains to.
using YamlOpener = std::function<YamlReader(const std::string& path)>;

}  // namespace dem_mobility::core
