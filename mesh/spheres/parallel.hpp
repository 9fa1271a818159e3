#pragma once
/// A minimal parallel loop for the sphere-tree builder: independent tasks
/// (one node each) handed out in index order to a few std::threads.
#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace icd::mesh {

/// Worker threads for `requested` (0: the hardware's concurrency, at least 1).
inline int worker_count(int requested) {
  if (requested > 0) return requested;
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

/// Calls task(i, worker) for every i in [0, n), on `workers` threads (the
/// calling thread is worker 0; worker < workers). Tasks must not depend on
/// each other or on the order they run in; each should write only its own
/// result. The first exception a task throws is rethrown here after every
/// thread has stopped (tasks not yet started are skipped).
template <class Task>
void parallel_for(size_t n, int workers, Task&& task) {
  const int threads =
      static_cast<int>(std::min<size_t>(n, static_cast<size_t>(std::max(workers, 1))));
  if (threads <= 1) {
    for (size_t i = 0; i < n; ++i) task(i, 0);
    return;
  }
  std::atomic<size_t> next{0};
  std::atomic<bool> failed{false};
  std::exception_ptr error;
  std::mutex error_mutex;
  auto work = [&](int worker) {
    for (size_t i = next++; i < n && !failed; i = next++) {
      try {
        task(i, worker);
      } catch (...) {
        const std::lock_guard<std::mutex> lock(error_mutex);
        if (!error) error = std::current_exception();
        failed = true;
      }
    }
  };
  std::vector<std::thread> pool;
  for (int w = 1; w < threads; ++w) pool.emplace_back(work, w);
  work(0);
  for (std::thread& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace icd::mesh
