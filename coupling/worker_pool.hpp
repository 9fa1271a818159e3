#pragma once
/// A small persistent pool of worker threads for the World's per-object
/// stages. Between jobs a worker may spin for a while (spin_seconds) before
/// it blocks; by default it blocks at once. Measured on the 2-vCPU machine
/// (bench_realtime, "hand-off"): waking a blocked worker costs ~6 us per
/// hand-off, while at load 9 a 100 us spin made the median hand-off 211 us
/// (the spinning threads take the cores their partners need; OpenMP's
/// unbounded default spin-wait made the 2-thread main job 6x slower than 1
/// thread at load 8).
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace icd::coupling {

class WorkerPool {
 public:
  /// Spin before blocking, s: none (see above).
  static constexpr double kDefaultSpin = 0;
  /// `threads` >= 1 in all, the calling thread included (threads - 1
  /// workers); `spin_seconds` >= 0 (0: block at once).
  explicit WorkerPool(int threads, double spin_seconds = kDefaultSpin);
  ~WorkerPool();
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  int threads() const { return static_cast<int>(m_workers.size()) + 1; }
  /// Runs f(k) once for every k in [0, n) on the caller and the workers and
  /// returns when all are done. Which thread runs which k is not fixed: f(k)
  /// must touch only what belongs to k. f must not throw. The caller takes
  /// k = 0 first. It waits for the tasks, not for every worker: a worker
  /// still waking up (or not scheduled: a loaded machine) when the others
  /// have done every task joins no job, and the caller does not wait for it.
  void run(int n, const std::function<void(int)>& f);

 private:
  void work();
  /// Takes indices of the current job until none is left.
  void drain(const std::function<void(int)>& f, int n);

  std::vector<std::thread> m_workers;
  std::mutex m_mutex;
  std::condition_variable m_start, m_done;
  double m_spin = 0;
  const std::function<void(int)>* m_job = nullptr;
  int m_n = 0;
  std::atomic<int> m_next{0};  ///< next index to take
  /// Tasks of the current job done (a worker taking the last one notifies
  /// under m_mutex), workers that joined the job and have not left it, and
  /// the job counter: m_busy and m_generation change under m_mutex (for the
  /// condition variables); all three are read while spinning.
  std::atomic<int> m_finished{0};
  std::atomic<int> m_busy{0};
  std::atomic<uint64_t> m_generation{0};
  std::atomic<bool> m_stop{false};
};

}  // namespace icd::coupling
