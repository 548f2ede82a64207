#include "dem_mobility/core/common/result_file.h"

#include <filesystem>
#include <fstream>

#include "dem_mobility/core/common/error.h"

namespace dem_mobility::core {

ResultFile::ResultFile(const std::string& scene_file, const std::string& kind)
    : scene_(scene_file), kind_(kind), body_(YAML::NodeType::Map) {}

bool ResultFile::Reserved(const std::string& key) {
  return key == "scene" || key == "kind" || key == "status" || key == "error";
}

void ResultFile::SetStatus(const std::string& status, const std::string& error) {
  status_ = status;
  error_ = error;
}

ResultFile& ResultFile::SetFlow(const std::string& key, const std::vector<double>& values) {
  DM_DEMAND(!Reserved(key));
  YAML::Node n(YAML::NodeType::Sequence);
  for (double v : values) n.push_back(v);
  n.SetStyle(YAML::EmitterStyle::Flow);
  body_[key] = n;
  return *this;
}

ResultFile& ResultFile::SetCounts(const std::string& key, const std::vector<std::pair<std::string, long>>& counts) {
  DM_DEMAND(!Reserved(key));
  YAML::Node n(YAML::NodeType::Map);
  for (const auto& [name, count] : counts) n[name] = count;
  body_[key] = n;
  return *this;
}

ResultFile& ResultFile::SetColumns(const std::string& key,
                                   const std::vector<std::pair<std::string, std::vector<double>>>& cols) {
  DM_DEMAND(!Reserved(key));
  YAML::Node n(YAML::NodeType::Map);
  for (const auto& [name, values] : cols) {
    YAML::Node c(YAML::NodeType::Sequence);
    for (double v : values) c.push_back(v);
    c.SetStyle(YAML::EmitterStyle::Flow);
    n[name] = c;
  }
  body_[key] = n;
  return *this;
}

std::string ResultFile::Text() const {
  YAML::Emitter e;
  e.SetDoublePrecision(17);
  e << YAML::BeginMap;
  e << YAML::Key << "scene" << YAML::Value << scene_;
  e << YAML::Key << "kind" << YAML::Value << kind_;
  e << YAML::Key << "status" << YAML::Value << status_;
  e << YAML::Key << "error" << YAML::Value << error_;
  for (const auto& kv : body_) e << YAML::Key << kv.first << YAML::Value << kv.second;
  e << YAML::EndMap;
  return std::string(e.c_str()) + "\n";
}

ResultFile& ResultFile::SetLedger(const std::string& prefix, const LedgerWatch& w) {
  Set(prefix + "_dissipated", w.dissipated);
  Set(prefix + "_dissipated_least", w.least);
  Set(prefix + "_dissipated_least_time", w.least_time);
  Set(prefix + "_largest_fall", w.largest_fall);
  Set(prefix + "_scale", w.Scale());
  return Set(prefix + "_samples", w.samples);
}

void ResultFile::Write(const std::string& path) const {
  std::ofstream out(path);
  if (!out) throw ConfigError(path + ": cannot write the result file");
  out << Text();
  out.flush();
  if (!out) throw ConfigError(path + ": writing the result file failed (disk full or a file size limit?)");
}

void ResultFile::CheckWritable(const std::string& path, const std::string& what) {
  if (path.empty()) return;
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  std::error_code ec;
  if (!parent.empty()) std::filesystem::create_directories(parent, ec);
  if (!std::ofstream(path, std::ios::app))
    throw ConfigError((what.empty() ? "" : what + ": ") + path + ": cannot write the result file here");
}

}  // namespace dem_mobility::core
