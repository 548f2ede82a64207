#include "dem_mobility/core/common/state_archive.h"

#include <dlfcn.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

#include "dem_mobility/core/common/error.h"

namespace dem_mobility::core {

void StateWriter::Tag(const char* name) {
  const std::string s(name);
  StateField(*this, s);
}

void StateWriter::Raw(const void* p, size_t n) {
  out_->write(static_cast<const char*>(p), static_cast<std::streamsize>(n));
  bytes_ += n;
}

void StateWriter::Generator(const std::mt19937_64* g) {
  std::ostringstream os;
  os << *g;
  const std::string s = os.str();
  StateField(*this, s);
}

void StateReader::Fail(const std::string& what) const {
  throw ConfigError(file_ + ": checkpoint: " + what + " (in its part '" + tag_ +
                    "'; a checkpoint of another build, another scene, or a damaged file)");
}

void StateReader::Expect(long found, long expected, const char* what) const {
  if (found != expected)
    Fail(detail::Concat(what, ": the checkpoint has ", found, ", the scene as built has ", expected));
}

void StateReader::Tag(const char* name) {
  std::string s;
  size_t n = 0;
  Count(&n, 1, "a part's name");
  if (n > 256) Fail(detail::Concat("a part's name of ", n, " bytes where part '", name, "' should begin"));
  s.resize(n);
  Raw(s.data(), n);
  if (s != name) Fail("part '" + std::string(name) + "' expected, found '" + s + "'");
  tag_ = name;
}

void StateReader::Raw(void* p, size_t n) {
  if (n > left_) Fail(detail::Concat("the file ends ", n - left_, " bytes early"));
  in_->read(static_cast<char*>(p), static_cast<std::streamsize>(n));
  if (static_cast<size_t>(in_->gcount()) != n) Fail("the file could not be read to its end");
  left_ -= n;
}

void StateReader::Count(size_t* n, size_t element_bytes, const char* what) {
  Raw(n, sizeof(*n));
  if (element_bytes > 0 && *n > left_ / element_bytes)
    Fail(detail::Concat(what, " of ", *n, " entries, more than the ", left_,
                        " bytes left of the file hold: the file ends early, or this is not where the list was"));
}

void StateReader::Generator(std::mt19937_64* g) {
  std::string s;
  StateField(*this, s);
  std::istringstream is(s);
  is >> *g;
  if (!is) Fail("the random generator's state does not read back");
}

uint64_t Fnv1a(const void* data, size_t n, uint64_t h) {
  const unsigned char* p = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < n; ++i) {
    h ^= p[i];
    h *= 0x100000001b3ULL;
  }
  return h;
}

uint64_t FileFingerprint(const std::string& path, bool* ok) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    if (ok) *ok = false;
    return 0;
  }
  uint64_t h = 0xcbf29ce484222325ULL;
  char buf[1 << 16];
  while (in) {
    in.read(buf, sizeof buf);
    h = Fnv1a(buf, static_cast<size_t>(in.gcount()), h);
  }
  if (ok) *ok = in.eof();
  return h;
}

uint64_t ExecutableFingerprint() {
  static const uint64_t h = [] {
    // the object this function is in: a shared library (the nodelets'), or the executable
    std::string file = "/proc/self/exe";
    Dl_info info;
    if (dladdr(reinterpret_cast<void*>(&ExecutableFingerprint), &info) != 0 && info.dli_fname) {
      const std::string f = info.dli_fname;
      if (f.find(".so") != std::string::npos) file = f;
    }
    bool ok = false;
    const uint64_t f = FileFingerprint(file, &ok);
    return ok ? f : 0;
  }();
  return h;
}

std::string SealState(const std::string& magic, uint32_t format, const std::string& state) {
  std::string bytes = magic;
  bytes.append(reinterpret_cast<const char*>(&format), sizeof(format));
  bytes += state;
  const uint64_t sum = Fnv1a(bytes.data(), bytes.size());
  bytes.append(reinterpret_cast<const char*>(&sum), sizeof(sum));
  return bytes;
}

std::string OpenSealedState(const std::string& path, const std::string& magic, uint32_t format,
                            const std::string& kind) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw ConfigError(path + ": cannot open the " + kind + " (missing, unreadable or not a file)");
  std::ifstream file(path, std::ios::binary);
  if (!file) throw ConfigError(path + ": cannot open the " + kind + " (missing or unreadable)");
  const std::string bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  const size_t head = magic.size() + sizeof(format);
  if (bytes.size() < head + sizeof(uint64_t) || bytes.compare(0, magic.size(), magic) != 0)
    throw ConfigError(path + ": not a dem_mobility " + kind);
  uint32_t found = 0;
  std::memcpy(&found, bytes.data() + magic.size(), sizeof(found));
  if (found != format)
    throw ConfigError(path + ": " + kind + " format " + std::to_string(found) + ", this program reads format " +
                      std::to_string(format));
  uint64_t sum = 0;
  std::memcpy(&sum, bytes.data() + bytes.size() - sizeof(sum), sizeof(sum));
  if (sum != Fnv1a(bytes.data(), bytes.size() - sizeof(sum)))
    throw ConfigError(path + ": the " + kind + " is damaged (its checksum does not match its bytes: cut short, or "
                             "changed since it was written)");
  return bytes.substr(head, bytes.size() - head - sizeof(sum));
}

void WriteFileAtomically(const std::string& path, const std::string& bytes) {
  // (a name of this process's own: two processes may write the same file at once)
  const std::string tmp = path + ".writing." + std::to_string(::getpid());
  {
    std::FILE* f = std::fopen(tmp.c_str(), "wb");
    if (!f) throw ConfigError(path + ": cannot write the checkpoint (" + std::strerror(errno) + ")");
    const bool wrote = std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size() && std::fflush(f) == 0 &&
                       ::fsync(fileno(f)) == 0;
    const int err = errno;
    if (std::fclose(f) != 0 || !wrote) {
      std::remove(tmp.c_str());
      throw ConfigError(path + ": writing the checkpoint failed (" + std::strerror(err) +
                        "; disk full or a file size limit?); the previous checkpoint, if any, is kept");
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const int err = errno;
    std::remove(tmp.c_str());
    throw ConfigError(path + ": cannot put the checkpoint in place (" + std::strerror(err) + ")");
  }
}

}  // namespace dem_mobility::core
