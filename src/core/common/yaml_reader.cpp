#include "dem_mobility/core/common/yaml_reader.h"
#include "dem_mobility/core/common/input_files.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <utility>

namespace dem_mobility::core {

namespace {
std::string Show(const YAML::Node& n) {
  if (!n.IsDefined() || n.IsNull()) return "(nothing)";
  if (n.IsScalar()) return "'" + n.Scalar() + "'";
  YAML::Emitter e;
  e << YAML::Flow << n;
  return e.c_str();
}
std::string Dirname(const std::string& p) {
  const auto pos = p.find_last_of('/');
  return pos == std::string::npos ? std::string(".") : p.substr(0, pos);
}
}  // namespace

YamlReader::YamlReader(YAML::Node node, std::string file, std::string path)
    : node_(std::move(node)),
      file_(std::move(file)),
      path_(std::move(path)),
      used_(std::make_shared<std::set<std::string>>()),
      overridden_(std::make_shared<std::set<std::string>>()) {}

YamlReader YamlReader::Load(const std::string& path) {
  // a configuration file is a regular file of modest size (a folder or a device such as /dev/zero,
  // named by mistake, would read as nothing or without end)
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status)) throw ConfigError(path + ": cannot open file (missing or unreadable)");
  if (!std::filesystem::is_regular_file(status)) throw ConfigError(path + ": not a regular file (a folder or a device?)");
  const auto bytes = std::filesystem::file_size(path, ec);
  if (!ec && bytes > kMaxFileBytes)
    throw ConfigError(path + ": " + std::to_string(bytes) + " bytes, more than a configuration file may have (" +
                      std::to_string(kMaxFileBytes) + ")");
  std::ifstream in(path);
  if (!in) throw ConfigError(path + ": cannot open file (missing or unreadable)");
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  NoteInputFile(path, text);  // (what a checkpoint records of the run: common/input_files.h)
  return FromString(text, path);
}

YamlReader YamlReader::LoadWithOverrides(const std::string& path, const std::vector<std::string>& overrides) {
  YamlReader r = Load(path);
  for (const std::string& kv : overrides) {
    const auto eq = kv.find('=');
    if (eq == std::string::npos || eq == 0) throw ConfigError(path + ": override '" + kv + "': expected key=value");
    const std::string key = kv.substr(0, eq), value = kv.substr(eq + 1);
    std::vector<std::string> parts;
    size_t start = 0, dot;
    while ((dot = key.find('.', start)) != std::string::npos) {
      parts.push_back(key.substr(start, dot - start));
      start = dot + 1;
    }
    parts.push_back(key.substr(start));
    r.overridden_->insert(key);
    YAML::Node node = r.node_;
    for (size_t i = 0; i + 1 < parts.size(); ++i) {
      YAML::Node next = node[parts[i]];
      // a map the file lacks is added (as a key is: the reader then rejects it if it is unknown)
      if (!next.IsDefined() || next.IsNull()) {
        node[parts[i]] = YAML::Node(YAML::NodeType::Map);
        next = node[parts[i]];
      }
      if (!next.IsMap()) throw ConfigError(path + ": override '" + kv + "': '" + parts[i] + "' is not a map in the file");
      node.reset(next);
    }
    try {
      node[parts.back()] = YAML::Load(value);
    } catch (const YAML::Exception& e) {
      throw ConfigError(path + ": override '" + kv + "': malformed value: " + e.what());
    }
  }
  return r;
}

std::string YamlReader::Dump() const { return YAML::Dump(node_); }

YamlReader YamlReader::FromString(const std::string& text, const std::string& name) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw ConfigError(name + ": malformed YAML: " + e.what());
  }
  if (!root.IsMap()) throw ConfigError(name + ": the top level must be a map of keys");
  return YamlReader(root, name, "");
}

std::string YamlReader::Where(const std::string& key) const {
  std::string p = path_.empty() ? key : (key.empty() ? path_ : path_ + "." + key);
  return file_ + ": " + (p.empty() ? "(top level)" : p);
}

void YamlReader::Fail(const std::string& key, const std::string& message) const {
  throw ConfigError(Where(key) + ": " + message);
}

bool YamlReader::Has(const std::string& key) const {
  if (!node_.IsMap()) return false;
  const YAML::Node n = node_[key];
  if (n.IsDefined()) used_->insert(key);
  return n.IsDefined() && !n.IsNull();
}

bool YamlReader::Overridden(const std::string& key) const {
  return overridden_->count(path_.empty() ? key : path_ + "." + key) > 0;
}

YAML::Node YamlReader::Get(const std::string& key) const {
  if (!node_.IsMap()) Fail("", "expected a map of keys, found " + Show(node_));
  const YAML::Node n = node_[key];
  if (!n.IsDefined() || n.IsNull()) Fail(key, "missing required key");
  used_->insert(key);
  return n;
}

template <typename T>
T YamlReader::As(const std::string& key, const YAML::Node& n, const char* what) const {
  try {
    if (!n.IsScalar()) throw YAML::Exception(YAML::Mark(), "not a scalar");
    return n.as<T>();
  } catch (const YAML::Exception&) {
    Fail(key, std::string("expected ") + what + ", found " + Show(n));
  }
}

double YamlReader::Double(const std::string& key) const {
  const double v = As<double>(key, Get(key), "a number");
  if (!std::isfinite(v)) Fail(key, "value " + Show(node_[key]) + " is not finite");
  return v;
}
double YamlReader::Double(const std::string& key, double fallback) const {
  return Has(key) ? Double(key) : fallback;
}
double YamlReader::DoubleIn(const std::string& key, double lo, double hi) const {
  const double v = Double(key);
  if (v < lo || v > hi)
    Fail(key, detail::Concat("value ", v, " is outside the allowed range [", lo, ", ", hi, "]"));
  return v;
}
double YamlReader::DoubleIn(const std::string& key, double lo, double hi, double fallback) const {
  return Has(key) ? DoubleIn(key, lo, hi) : fallback;
}
double YamlReader::Positive(const std::string& key) const {
  const double v = Double(key);
  if (!(v > 0.0)) Fail(key, detail::Concat("value ", v, " must be positive"));
  return v;
}
double YamlReader::Positive(const std::string& key, double fallback) const {
  return Has(key) ? Positive(key) : fallback;
}
double YamlReader::NonNegative(const std::string& key) const {
  const double v = Double(key);
  if (v < 0.0) Fail(key, detail::Concat("value ", v, " must not be negative"));
  return v;
}
double YamlReader::NonNegative(const std::string& key, double fallback) const {
  return Has(key) ? NonNegative(key) : fallback;
}
int YamlReader::Int(const std::string& key) const { return As<int>(key, Get(key), "an integer"); }
int YamlReader::Int(const std::string& key, int fallback) const {
  return Has(key) ? Int(key) : fallback;
}
bool YamlReader::Bool(const std::string& key, bool fallback) const {
  return Has(key) ? As<bool>(key, Get(key), "true or false") : fallback;
}
std::string YamlReader::String(const std::string& key) const {
  return As<std::string>(key, Get(key), "a string");
}
std::string YamlReader::String(const std::string& key, const std::string& fallback) const {
  return Has(key) ? String(key) : fallback;
}

std::vector<double> YamlReader::DoubleList(const std::string& key) const {
  const YAML::Node n = Get(key);
  if (!n.IsSequence()) Fail(key, "expected a list of numbers, found " + Show(n));
  std::vector<double> out;
  for (size_t i = 0; i < n.size(); ++i) {
    try {
      out.push_back(n[i].as<double>());
    } catch (const YAML::Exception&) {
      Fail(key, "element " + std::to_string(i) + " is not a number: " + Show(n[i]));
    }
    if (!std::isfinite(out.back())) Fail(key, "element " + std::to_string(i) + " is not finite");
  }
  return out;
}

Eigen::Vector3d YamlReader::Vector3(const std::string& key) const {
  const std::vector<double> v = DoubleList(key);
  if (v.size() != 3) Fail(key, "expected 3 numbers [x, y, z], found " + Show(node_[key]));
  return {v[0], v[1], v[2]};
}
Eigen::Vector3d YamlReader::Vector3(const std::string& key, const Eigen::Vector3d& fallback) const {
  return Has(key) ? Vector3(key) : fallback;
}

Table1D YamlReader::Table(const std::string& key) const {
  const YAML::Node n = Get(key);
  if (!n.IsSequence() || n.size() == 0)
    Fail(key, "expected a non-empty list of [x, y] pairs, found " + Show(n));
  std::vector<double> x, y;
  for (size_t i = 0; i < n.size(); ++i) {
    if (!n[i].IsSequence() || n[i].size() != 2)
      Fail(key, "row " + std::to_string(i) + " must be a pair [x, y], found " + Show(n[i]));
    try {
      x.push_back(n[i][0].as<double>());
      y.push_back(n[i][1].as<double>());
    } catch (const YAML::Exception&) {
      Fail(key, "row " + std::to_string(i) + " is not a pair of numbers: " + Show(n[i]));
    }
  }
  try {
    return Table1D(x, y, Where(key));
  } catch (const ConfigError& e) {
    throw;
  }
}

std::string YamlReader::KeyText(const YAML::Node& key) const {
  // a key is a word; YAML also allows a list or a map as a key (`? [a, b]: 1`), which no file of ours has
  if (!key.IsScalar()) Fail("", "a key must be a plain word, found " + Show(key));
  return key.Scalar();
}

std::vector<std::string> YamlReader::Keys() const {
  std::vector<std::string> keys;
  for (const auto& kv : node_) keys.push_back(KeyText(kv.first));
  return keys;
}

bool YamlReader::IsMap(const std::string& key) const { return node_.IsMap() && node_[key] && node_[key].IsMap(); }

bool YamlReader::IsList(const std::string& key) const {
  return node_.IsMap() && node_[key] && node_[key].IsSequence();
}

std::string YamlReader::FlowText(const std::string& key) const {
  YAML::Emitter e;
  e.SetSeqFormat(YAML::Flow);
  e.SetMapFormat(YAML::Flow);
  e << Get(key);
  return e.c_str();
}

YamlReader YamlReader::Child(const std::string& key) const {
  const YAML::Node n = Get(key);
  if (!n.IsMap()) Fail(key, "expected a map of keys, found " + Show(n));
  YamlReader child(n, file_, path_.empty() ? key : path_ + "." + key);
  child.overridden_ = overridden_;
  return child;
}

std::string YamlReader::ResolvePath(const std::string& relative) const {
  if (!relative.empty() && relative[0] == '/') return relative;
  return Dirname(file_) + "/" + relative;
}

namespace {
/// Names a thing had before it got its one name: a file's own key (a scene's, a terrain's; what
/// a launch argument or a command-line override sets) given the old way is refused, the message
/// naming the new one.
const std::pair<const char*, const char*> kRenamed[] = {
    {"f", "cohesion_factor"}, {"mu", "friction"}, {"grade", "grade_deg"}, {"ci", "cone_index"},
    {"ci_psi", "cone_index"}, {"requested_ci", "cone_index"}, {"cone_index_psi", "cone_index"}};
}  // namespace

void YamlReader::Finish() const {
  if (!node_.IsMap()) return;
  std::string unknown;
  for (const auto& kv : node_) {
    const std::string k = KeyText(kv.first);
    if (used_->count(k)) continue;
    unknown += (unknown.empty() ? "" : ", ") + k;
    if (path_.empty())  // (a file's own keys: a nested map's may mean another thing by the name)
      for (const auto& [old_name, name] : kRenamed)
        if (k == old_name) unknown += std::string(" (now ") + name + ")";
  }
  if (!unknown.empty()) Fail("", "unknown key(s): " + unknown);
}

}  // namespace dem_mobility::core
