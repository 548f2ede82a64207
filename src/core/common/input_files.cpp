#include "dem_mobility/core/common/input_files.h"

#include <filesystem>
#include <mutex>
#include <set>

#include "dem_mobility/core/common/state_archive.h"

namespace dem_mobility::core {

namespace {
std::mutex g_mutex;
std::vector<InputFile> g_files;

std::string Absolute(const std::string& path) {
  std::error_code ec;
  const std::filesystem::path a = std::filesystem::absolute(path, ec);
  return ec ? path : a.lexically_normal().string();
}
}  // namespace

void NoteInputFile(const std::string& path, const std::string& bytes) {
  InputFile f{Absolute(path), Fnv1a(bytes.data(), bytes.size())};
  std::lock_guard<std::mutex> lock(g_mutex);
  g_files.push_back(std::move(f));
}

void NoteInputFile(const std::string& path) {
  bool ok = false;
  InputFile f{Absolute(path), FileFingerprint(path, &ok)};
  std::lock_guard<std::mutex> lock(g_mutex);
  g_files.push_back(std::move(f));
}

size_t InputFileCount() {
  std::lock_guard<std::mutex> lock(g_mutex);
  return g_files.size();
}

std::vector<InputFile> InputFilesSince(size_t mark) {
  std::lock_guard<std::mutex> lock(g_mutex);
  std::vector<InputFile> out;
  std::set<std::string> seen;
  for (size_t i = mark; i < g_files.size(); ++i)
    if (seen.insert(g_files[i].path).second) out.push_back(g_files[i]);
  return out;
}

}  // namespace dem_mobility::core
