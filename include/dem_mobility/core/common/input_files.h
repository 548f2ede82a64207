// The input files a process has read (configuration YAML, meshes), each with the fingerprint of
// the bytes it read: what a checkpoint records of the run it holds, so that a restart can refuse
// to go on with any of them changed (common/state_archive.h, common/checkpoint.h).
//
// A file read is noted only in the records alive at that moment (InputFileRecord), each path once:
// a process that loads files again and again without a record (a fuzzer, a node that reloads its
// scene) keeps nothing of them, and a record holds no more than the distinct files it saw.
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

/// Notes that `path` was read with these bytes in every record alive now (thread-safe).
void NoteInputFile(const std::string& path, const std::string& bytes);
/// The same, fingerprinting the file as it is on disk now (a reader that streams it).
void NoteInputFile(const std::string& path);

/// Records the files read while it lives, by any thread. Records nest: a file read while two are
/// alive is in both.
class InputFileRecord {
 public:
  InputFileRecord();
  ~InputFileRecord();
  InputFileRecord(const InputFileRecord&) = delete;
  InputFileRecord& operator=(const InputFileRecord&) = delete;
  /// The files read since it began, each path once (its first reading), in the order read.
  std::vector<InputFile> Files() const;

 private:
  friend void NoteInputFile(const std::string& path, const std::string& bytes);
  friend void NoteInputFile(const std::string& path);
  /// Adds `f` to every record alive unless its path is there already.
  static void Note(const InputFile& f);
  std::vector<InputFile> files_;
};

}  // namespace dem_mobility::core
