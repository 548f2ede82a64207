// A run's state in binary (a checkpoint), written and read by one description per class.
//
// Every stateful class has `template <class Ar> void Io(Ar& ar)` that names its state fields in
// order, `ar(a, b, c)`, and optionally `ar.Tag("name")` between groups. StateWriter writes them and
// StateReader reads them back in the same order, so the two can never disagree about the layout;
// a tag that does not match, a count larger than what is left of the file, or a file that ends
// early is a ConfigError naming the file and what was being read (a checkpoint of another build or
// another scene, or a damaged one), never a crash or a half-loaded state.
//
// A field is one of: arithmetic, enum, fixed-size Eigen matrix, quaternion, std::string,
// std::array, std::pair, std::vector of any of them, a struct marked `using StateBulk = void;`
// (plain data of those, copied as bytes), or a class with its own Io.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <cstring>
#include <iosfwd>
#include <random>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace dem_mobility::core {

namespace state_detail {
template <class T, class = void>
struct MarkedBulk : std::false_type {};
template <class T>
struct MarkedBulk<T, std::void_t<typename T::StateBulk>> : std::true_type {};
template <class T>
struct IsEigenFixed : std::false_type {};
template <class S, int R, int C, int O, int MR, int MC>
struct IsEigenFixed<Eigen::Matrix<S, R, C, O, MR, MC>> : std::bool_constant<(R > 0 && C > 0)> {};
template <class T>
struct IsVector : std::false_type {};
template <class T, class A>
struct IsVector<std::vector<T, A>> : std::true_type {};
template <class T>
struct IsArray : std::false_type {};
template <class T, size_t N>
struct IsArray<std::array<T, N>> : std::true_type {};
template <class T>
struct IsPair : std::false_type {};
template <class A, class B>
struct IsPair<std::pair<A, B>> : std::true_type {};
/// The fewest bytes an element of a list takes in the file (bounds a count against the file's size).
template <class T>
constexpr size_t MinBytes() {
  if constexpr (IsVector<T>::value || std::is_same_v<T, std::string>) return sizeof(size_t);
  return 1;
}
}  // namespace state_detail

/// Whether a field is copied as its bytes.
template <class T>
constexpr bool kStateBulk = std::is_arithmetic_v<T> || std::is_enum_v<T> || state_detail::IsEigenFixed<T>::value ||
                            state_detail::MarkedBulk<T>::value;

/// The fields of a state, in order, in either direction (Ar: StateWriter or StateReader).
template <class Ar, class T>
void StateField(Ar& ar, T& v) {
  using U = std::remove_const_t<T>;
  U& u = const_cast<U&>(v);
  if constexpr (kStateBulk<U>) {
    ar.Raw(&u, sizeof(U));
  } else if constexpr (std::is_same_v<U, Eigen::Quaterniond>) {
    ar.Raw(u.coeffs().data(), sizeof(double) * 4);
  } else if constexpr (std::is_same_v<U, std::string>) {
    size_t n = u.size();
    ar.Count(&n, 1, "a string");
    if constexpr (Ar::kLoading) u.resize(n);
    ar.Raw(u.data(), n);
  } else if constexpr (std::is_same_v<U, std::mt19937_64>) {
    ar.Generator(&u);
  } else if constexpr (state_detail::IsVector<U>::value) {
    using E = typename U::value_type;
    static_assert(!std::is_same_v<E, bool>, "std::vector<bool> has no bytes to copy: use unsigned char");
    size_t n = u.size();
    ar.Count(&n, kStateBulk<E> ? sizeof(E) : state_detail::MinBytes<E>(), "a list");
    if constexpr (Ar::kLoading) u.resize(n);
    if constexpr (kStateBulk<E>) {
      if (n > 0) ar.Raw(u.data(), n * sizeof(E));
    } else {
      for (E& e : u) StateField(ar, e);
    }
  } else if constexpr (state_detail::IsArray<U>::value) {
    for (auto& e : u) StateField(ar, e);
  } else if constexpr (state_detail::IsPair<U>::value) {
    StateField(ar, u.first);
    StateField(ar, u.second);
  } else {
    u.Io(ar);
  }
}

/// Writes a state to a stream (in memory; WriteStateFile puts it on disk).
class StateWriter {
 public:
  static constexpr bool kLoading = false;
  explicit StateWriter(std::ostream* out) : out_(out) {}
  template <class... T>
  void operator()(T&... v) {
    (StateField(*this, v), ...);
  }
  /// A named mark the reader checks (names the part that does not match).
  void Tag(const char* name);
  void Raw(const void* p, size_t n);
  void Count(const size_t* n, size_t /*element_bytes*/, const char* /*what*/) { Raw(n, sizeof(*n)); }
  void Generator(const std::mt19937_64* g);
  /// A size the built scene fixes (walls, bodies, triangles): the reader checks it is the same.
  void Same(long v, const char* /*what*/) { Raw(&v, sizeof v); }
  uint64_t bytes() const { return bytes_; }

 private:
  std::ostream* out_;
  uint64_t bytes_ = 0;
};

/// Reads a state written by StateWriter; ConfigError naming `file` (and the last tag passed) when
/// it does not match what is being read.
class StateReader {
 public:
  static constexpr bool kLoading = true;
  /// `size`: the bytes the stream holds from here (bounds every count).
  StateReader(std::istream* in, std::string file, uint64_t size) : in_(in), file_(std::move(file)), left_(size) {}
  template <class... T>
  void operator()(T&... v) {
    (StateField(*this, v), ...);
  }
  void Tag(const char* name);
  void Raw(void* p, size_t n);
  void Count(size_t* n, size_t element_bytes, const char* what);
  void Generator(std::mt19937_64* g);
  void Same(long v, const char* what) {
    long found = 0;
    Raw(&found, sizeof found);
    Expect(found, v, what);
  }
  /// Throws ConfigError: "FILE: checkpoint: WHAT (in part TAG)".
  [[noreturn]] void Fail(const std::string& what) const;
  /// Fails unless `found` equals `expected` (a size the built objects fix: walls, bodies, ...).
  void Expect(long found, long expected, const char* what) const;
  const std::string& file() const { return file_; }
  uint64_t left() const { return left_; }

 private:
  std::istream* in_;
  std::string file_;
  uint64_t left_;
  std::string tag_ = "(start)";
};

/// FNV-1a, 64 bits (file fingerprints).
uint64_t Fnv1a(const void* data, size_t n, uint64_t h = 0xcbf29ce484222325ULL);
/// The fingerprint of a file's bytes; `ok` false when it cannot be read.
uint64_t FileFingerprint(const std::string& path, bool* ok);
/// The fingerprint of the build of this code that runs: the shared object it is linked into (the
/// ROS nodelets' library), or the executable (dm_run_scene, the tests): a restart must run the
/// same build, and a prepared soil is reused only by it. 0 when the file cannot be read.
uint64_t ExecutableFingerprint();

/// A state in a file of its own kind: `magic` (a line naming the kind), the format's version, the
/// state's bytes, and the Fnv1a of all the bytes before it.
std::string SealState(const std::string& magic, uint32_t format, const std::string& state);
/// The state of a file SealState wrote; ConfigError naming `path` when it is missing, of another
/// kind or format, or damaged (its checksum does not match).
std::string OpenSealedState(const std::string& path, const std::string& magic, uint32_t format,
                            const std::string& kind);

/// Writes `bytes` to `path` through a temporary file in the same folder and a rename, so that a
/// process killed while writing leaves the previous file whole; ConfigError naming the path.
void WriteFileAtomically(const std::string& path, const std::string& bytes);

}  // namespace dem_mobility::core
