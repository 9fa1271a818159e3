#pragma once
/// A small persistent pool of worker threads for the World's per-object
/// stages. The workers block (no spinning) between jobs: on a machine shared
/// with other processes a spinning worker takes the core its partner needs
/// (measured: OpenMP's default spin-wait made the 2-thread main job 6x
/// slower than 1 thread at load 8 on 2 cores; blocking workers do not).
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace icd::coupling {

class WorkerPool {
 public:
  /// `threads` >= 1 in all, the calling thread included (threads - 1 workers).
  explicit WorkerPool(int threads);
  ~WorkerPool();
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  int threads() const { return static_cast<int>(m_workers.size()) + 1; }
  /// Runs f(k) once for every k in [0, n) on the caller and the workers and
  /// returns when all are done. Which thread runs which k is not fixed: f(k)
  /// must touch only what belongs to k. f must not throw.
  void run(int n, const std::function<void(int)>& f);

 private:
  void work();
  /// Takes indices of the current job until none is left.
  void drain(const std::function<void(int)>& f, int n);

  std::vector<std::thread> m_workers;
  std::mutex m_mutex;
  std::condition_variable m_start, m_done;
  const std::function<void(int)>* m_job = nullptr;
  int m_n = 0;
  int m_next = 0;     ///< next index to take (under m_mutex)
  int m_busy = 0;     ///< workers still on the current job
  uint64_t m_generation = 0;
  bool m_stop = false;
};

}  // namespace icd::coupling
