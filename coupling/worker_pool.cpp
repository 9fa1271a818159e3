#include <icd/coupling/worker_pool.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>

#include <icd/mesh/core/error.hpp>

namespace icd::coupling {
namespace {

// Spins until done() or `seconds` have passed; true when done() held.
template <class Done>
bool spin_until(Done&& done, double seconds) {
  if (!(seconds > 0)) return done();
  using Clock = std::chrono::steady_clock;
  const Clock::time_point end =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
  for (int i = 0;; ++i) {
    if (done()) return true;
    if ((i & 63) == 63 && Clock::now() >= end) return done();
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#endif
  }
}

}  // namespace

WorkerPool::WorkerPool(int threads, double spin_seconds) : m_spin(spin_seconds) {
  if (threads < 1) throw ParameterError("WorkerPool: threads must be >= 1");
  if (!(spin_seconds >= 0) || !std::isfinite(spin_seconds))
    throw ParameterError("WorkerPool: spin_seconds must be >= 0 and finite");
  m_workers.reserve(static_cast<size_t>(threads - 1));
  for (int i = 1; i < threads; ++i) m_workers.emplace_back([this] { work(); });
}

WorkerPool::~WorkerPool() {
  {
    std::lock_guard<std::mutex> lock(m_mutex);
    m_stop = true;
  }
  m_start.notify_all();
  for (std::thread& t : m_workers) t.join();
}

void WorkerPool::drain(const std::function<void(int)>& f, int n) {
  for (;;) {
    const int k = m_next.fetch_add(1, std::memory_order_relaxed);
    if (k >= n) return;
    f(k);
    if (m_finished.fetch_add(1, std::memory_order_acq_rel) + 1 == n) {
      std::lock_guard<std::mutex> lock(m_mutex);  // (the caller may be waiting)
      m_done.notify_one();
    }
  }
}

void WorkerPool::run(int n, const std::function<void(int)>& f) {
  if (n <= 0) return;
  if (m_workers.empty() || n == 1) {
    for (int k = 0; k < n; ++k) f(k);
    return;
  }
  {
    std::lock_guard<std::mutex> lock(m_mutex);
    m_job = &f;
    m_n = n;
    m_next.store(0, std::memory_order_relaxed);
    m_finished.store(0, std::memory_order_relaxed);
    m_busy.store(0, std::memory_order_relaxed);
    m_generation.fetch_add(1, std::memory_order_release);
  }
  m_start.notify_all();
  drain(f, n);
  // Every task done and no worker inside the job. A worker joins only under
  // the lock while m_job is set, and the job is withdrawn under the same
  // lock as the last check: a late worker finds none and goes back to wait.
  const auto done = [&] {
    return m_finished.load(std::memory_order_acquire) == n &&
           m_busy.load(std::memory_order_acquire) == 0;
  };
  spin_until(done, m_spin);
  std::unique_lock<std::mutex> lock(m_mutex);
  m_done.wait(lock, done);
  m_job = nullptr;
}

void WorkerPool::work() {
  uint64_t seen = 0;
  for (;;) {
    spin_until(
        [&] {
          return m_stop.load(std::memory_order_acquire) ||
                 m_generation.load(std::memory_order_acquire) != seen;
        },
        m_spin);
    const std::function<void(int)>* job;
    int n;
    {
      std::unique_lock<std::mutex> lock(m_mutex);
      m_start.wait(lock, [&] { return m_stop.load() || m_generation.load() != seen; });
      if (m_stop) return;
      seen = m_generation.load();
      job = m_job;
      n = m_n;
      if (!job || m_next.load(std::memory_order_relaxed) >= n) continue;  // (done without it)
      m_busy.fetch_add(1, std::memory_order_relaxed);
    }
    drain(*job, n);
    {
      std::lock_guard<std::mutex> lock(m_mutex);
      if (m_busy.fetch_sub(1, std::memory_order_acq_rel) == 1) m_done.notify_one();
    }
  }
}

}  // namespace icd::coupling
