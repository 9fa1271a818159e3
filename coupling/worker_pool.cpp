#include <icd/coupling/worker_pool.hpp>

#include <algorithm>

#include <icd/mesh/core/error.hpp>

namespace icd::coupling {

WorkerPool::WorkerPool(int threads) {
  if (threads < 1) throw ParameterError("WorkerPool: threads must be >= 1");
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
    int k;
    {
      std::lock_guard<std::mutex> lock(m_mutex);
      if (m_next >= n) return;
      k = m_next++;
    }
    f(k);
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
    m_next = 0;
    m_busy = static_cast<int>(m_workers.size());
    ++m_generation;
  }
  m_start.notify_all();
  drain(f, n);
  std::unique_lock<std::mutex> lock(m_mutex);
  m_done.wait(lock, [this] { return m_busy == 0; });
  m_job = nullptr;
}

void WorkerPool::work() {
  uint64_t seen = 0;
  for (;;) {
    const std::function<void(int)>* job;
    int n;
    {
      std::unique_lock<std::mutex> lock(m_mutex);
      m_start.wait(lock, [&] { return m_stop || m_generation != seen; });
      if (m_stop) return;
      seen = m_generation;
      job = m_job;
      n = m_n;
    }
    drain(*job, n);
    bool last;
    {
      std::lock_guard<std::mutex> lock(m_mutex);
      last = --m_busy == 0;
    }
    if (last) m_done.notify_one();
  }
}

}  // namespace icd::coupling
