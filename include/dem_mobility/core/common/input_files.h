// The input files a process has read (configuration YAML, meshes), each with the fingerprint of
// the bytes it read: what a checkpoint records of the run it holds, so that a restart can refuse
// to go on with any of them changed (common/state_archive.h, mobility/checkpoint.h).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace dem_mobility::core {

struct InputFile {
  std::string path;          ///< absolute
  uint64_t fingerprint = 0;  ///< Fnv1a of its bytes as read
  template <class Ar>
  void Io(Ar& ar) {
    ar(path, fingerprint);
  }
};

/// Notes that `path` was read with these bytes (thread-safe).
void NoteInputFile(const std::string& path, const std::string& bytes);
/// The same, fingerprinting the file as it is on disk now (a reader that streams it).
void NoteInputFile(const std::string& path);
/// How many files have been noted so far (a mark for InputFilesSince).
size_t InputFileCount();
/// The files noted from `mark` on, each path once (its first reading), in the order read.
std::vector<InputFile> InputFilesSince(size_t mark);

}  // namespace dem_mobility::core
