#pragma once
/// Bounded stages of the preprocessing pipeline: each stage runs in a child
/// process with a CPU-time and an address-space limit, in a private scratch
/// folder, its standard streams discarded. A stage that exceeds a limit, runs
/// out of memory, fails inside CGAL or crashes ends in an InputError that
/// names the stage and the option that changes the limit; nothing CGAL prints
/// or writes (assertion text, dump-bug files) reaches the user or the working
/// folder. Plain POSIX (fork, pipe, setrlimit, wait4); Linux /proc for progress.
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <functional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include <icd/mesh/core/error.hpp>

namespace icd::mesh {

/// Limits of one stage.
struct StageLimits {
  double cpu_seconds = 120.0;  ///< CPU time (all threads) of one stage, s (> 0)
  double memory_mb = 4096.0;   ///< address space of the stage's process, MiB (> 0)
  /// Run the stage in a child process (false: in this process, no limits;
  /// for debugging only).
  bool isolate = true;
};

/// What a stage used (its child process: CPU of all threads, peak resident set).
struct StageUsage {
  double cpu_seconds = 0.0;
  double wall_seconds = 0.0;
  double peak_mb = 0.0;

  /// Adds the use of a later run: its times add up, the peak is the larger.
  StageUsage& operator+=(const StageUsage& other) {
    cpu_seconds += other.cpu_seconds;
    wall_seconds += other.wall_seconds;
    peak_mb = std::max(peak_mb, other.peak_mb);
    return *this;
  }
};

/// Thrown when a stage exceeded a limit (CPU time, memory) or failed inside a
/// library; the message names the stage, the limit and the option.
class StageError : public InputError {
 public:
  enum class Kind { cpu_limit, memory_limit, internal, crashed };
  StageError(Kind kind, const std::string& message) : InputError(message), m_kind(kind) {}
  Kind kind() const { return m_kind; }

 private:
  Kind m_kind;
};

/// Called about once per second after a stage's first second with a short
/// status ("3.1 s cpu, 412 MB").
using HeartbeatFn = std::function<void(const std::string& status)>;

/// Runs `work` under `limits` and returns the bytes it returned. `stage`
/// names the stage in messages; `hint` (may be empty) is appended to limit
/// and internal-failure messages (what else to try). InputError and
/// ParameterError thrown by `work` are rethrown with their message; a CPU or
/// memory limit, std::bad_alloc, a CGAL failure or a crash becomes a
/// StageError. `usage` (optional) receives what the stage used.
std::string run_bounded(const std::string& stage, const StageLimits& limits,
                        const std::function<std::string()>& work, StageUsage* usage = nullptr,
                        const HeartbeatFn& heartbeat = {}, const std::string& hint = "");

/// Minimal binary serialisation of stage results between processes (same
/// binary, same machine: no endianness or versioning).
class ByteWriter {
 public:
  template <class T>
  void pod(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    m_bytes.append(reinterpret_cast<const char*>(&v), sizeof(T));
  }
  template <class T>
  void vec(const std::vector<T>& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    pod<std::uint64_t>(v.size());
    m_bytes.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
  }
  template <class Derived>
  void mat(const Eigen::PlainObjectBase<Derived>& m) {
    pod<std::int64_t>(m.rows());
    pod<std::int64_t>(m.cols());
    m_bytes.append(reinterpret_cast<const char*>(m.data()),
                   static_cast<std::size_t>(m.size()) * sizeof(typename Derived::Scalar));
  }
  void str(const std::string& s) {
    pod<std::uint64_t>(s.size());
    m_bytes.append(s);
  }
  std::string take() { return std::move(m_bytes); }

 private:
  std::string m_bytes;
};

/// Reads what ByteWriter wrote, in the same order; throws InputError on a short read.
class ByteReader {
 public:
  explicit ByteReader(std::string bytes) : m_bytes(std::move(bytes)) {}
  template <class T>
  T pod() {
    T v;
    std::memcpy(&v, take(sizeof(T)), sizeof(T));
    return v;
  }
  template <class T>
  std::vector<T> vec() {
    const auto n = pod<std::uint64_t>();
    std::vector<T> v(n);
    if (n) std::memcpy(v.data(), take(n * sizeof(T)), n * sizeof(T));
    return v;
  }
  template <class M>
  M mat() {
    const auto r = pod<std::int64_t>(), c = pod<std::int64_t>();
    M m(r, c);
    const std::size_t n = static_cast<std::size_t>(r * c) * sizeof(typename M::Scalar);
    if (n) std::memcpy(m.data(), take(n), n);
    return m;
  }
  std::string str() {
    const auto n = pod<std::uint64_t>();
    return std::string(take(n), n);
  }

 private:
  const char* take(std::size_t n) {
    if (m_pos + n > m_bytes.size())
      throw InputError("ByteReader: truncated stage result (internal error)");
    const char* p = m_bytes.data() + m_pos;
    m_pos += n;
    return p;
  }
  std::string m_bytes;
  std::size_t m_pos = 0;
};

}  // namespace icd::mesh
