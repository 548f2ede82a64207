#include "dem_mobility/core/common/input_files.h"

#include <algorithm>
#include <filesystem>
#include <mutex>

#include "dem_mobility/core/common/state_archive.h"

namespace dem_mobility::core {

namespace {
std::mutex g_mutex;
std::vector<InputFileRecord*> g_records;  // the records alive, under g_mutex

bool AnyRecord() {
  std::lock_guard<std::mutex> lock(g_mutex);
  return !g_records.empty();
}

std::string Absolute(const std::string& path) {
  std::error_code ec;
  const std::filesystem::path a = std::filesystem::absolute(path, ec);
  return ec ? path : a.lexically_normal().string();
}
}  // namespace

void InputFileRecord::Note(const InputFile& f) {
  std::lock_guard<std::mutex> lock(g_mutex);
  for (InputFileRecord* r : g_records) {
    std::vector<InputFile>& files = r->files_;
    if (std::none_of(files.begin(), files.end(), [&](const InputFile& g) { return g.path == f.path; }))
      files.push_back(f);
  }
}

void NoteInputFile(const std::string& path, const std::string& bytes) {
  if (!AnyRecord()) return;  // (nothing to fingerprint for)
  InputFileRecord::Note(InputFile{Absolute(path), Fnv1a(bytes.data(), bytes.size())});
}

void NoteInputFile(const std::string& path) {
  if (!AnyRecord()) return;
  bool ok = false;
  InputFileRecord::Note(InputFile{Absolute(path), FileFingerprint(path, &ok)});
}

InputFileRecord::InputFileRecord() {
  std::lock_guard<std::mutex> lock(g_mutex);
  g_records.push_back(this);
}

InputFileRecord::~InputFileRecord() {
  std::lock_guard<std::mutex> lock(g_mutex);
  g_records.erase(std::find(g_records.begin(), g_records.end(), this));
}

std::vector<InputFile> InputFileRecord::Files() const {
  std::lock_guard<std::mutex> lock(g_mutex);
  return files_;
}

}  // namespace dem_mobility::core
