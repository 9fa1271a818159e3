// Budget overrun of the interruptible traversal (issues 6, 31): for budgets
// from 10 us to 100 ms, many queries each, for the paper's literal Fig. 7
// (clock read at every test) and for the fast path (clock every 16 tests,
// steady_clock or rdtsc). Every query falls in one class: completed (nothing
// left to refine, returned before the budget), stopped early (interrupted
// with work left before the budget was spent: how early, p50 / max) or
// overrun (interrupted at or after the budget: wall time of the call minus
// the budget, p50 / p99 / p99.9 / max over these only). An early stop is not
// counted as a punctual one. A second thread measures the floor in the same run: it spins on the
// clock towards deadlines of the same length and records how late it sees
// them (the time the VM takes the processor away), plus the gaps between
// consecutive reads.
//
// Usage: icd_collision_overrun [--queries N] [--max-seconds S] [--csv FILE]
//   N: queries per (configuration, budget), default 10000; S: time cap per
//   (configuration, budget), default 4 s (so 100 ms budgets run S/0.1 queries).
//   FILE is written whole at the end, atomically: a run stopped midway leaves none.
#include <atomic>
#include <chrono>
#include <cstdio>
#include <random>
#include <sstream>
#include <stop_token>
#include <string>
#include <thread>
#include <vector>

#include <icd/collision/traversal.hpp>
#include <icd/mesh/io/atomic_write.hpp>
#include "experiments/studies/collision/workloads.hpp"
#include "experiments/common/cli.hpp"
#include "experiments/common/guarded_main.hpp"

using namespace icd::collision;
using namespace icd::collision::experiments;
using icd::experiments::Clock;
using icd::experiments::seconds_since;

namespace {

void spin_for(double s) {
  const auto t0 = Clock::now();
  while (seconds_since(t0) < s) {
  }
}

// The floor: a thread that only spins on the clock. It waits for deadlines
// of the budget currently measured (plus the same random start jitter) and
// records how late it sees them, binned per budget, plus the gaps between
// consecutive clock reads.
struct Floor {
  std::atomic<int> bin{-1};  // index of the budget being measured, -1 = idle
  std::vector<double> budgets;
  std::vector<std::vector<double>> lateness;  // per budget, seconds past the deadline
  std::vector<double> gaps;                   // gaps > 1 us between consecutive clock reads
  double spun = 0;
  void run(const std::stop_token& stop) {
    std::mt19937 rng(42);
    std::uniform_real_distribution<double> jitter(0.0, 20e-6);
    lateness.assign(budgets.size(), {});
    const auto t_begin = Clock::now();
    auto prev = Clock::now();
    while (!stop.stop_requested()) {
      const int k = bin.load(std::memory_order_relaxed);
      const double wait = (k < 0 ? 10e-6 : budgets[k]) + jitter(rng);
      const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                               std::chrono::duration<double>(wait));
      for (;;) {
        const auto now = Clock::now();
        const double gap = std::chrono::duration<double>(now - prev).count();
        if (gap > 1e-6) gaps.push_back(gap);
        prev = now;
        if (now >= deadline) {
          if (k >= 0) lateness[k].push_back(std::chrono::duration<double>(now - deadline).count());
          break;
        }
      }
    }
    spun = seconds_since(t_begin);
  }
};

struct Config {
  std::string name;
  CollisionRequest request;
};

int run(int argc, char** argv) {
  long long max_queries = 10000;
  double max_seconds = 4.0;
  std::string csv_path;
  icd::experiments::Cli cli("icd_collision_overrun");
  cli.integer("--queries", max_queries, "N", "queries at most (default 10000)", 1LL)
      .real("--max-seconds", max_seconds, "S", "wall time at most (default 4)", 0.0)
      .text("--csv", csv_path, "FILE", "also write the measurements as CSV");
  if (const auto status = cli.parse(argc, argv)) return *status;
  // The CSV is built here and written whole at the end (checked writable first).
  const bool want_csv = !csv_path.empty();
  std::ostringstream csv;
  if (want_csv) {
    icd::check_writable(csv_path);
    csv << "config,budget_s,queries,completed,early,early_p50_us,early_max_us,overruns,p50_us,"
           "p99_us,p999_us,max_us,median_tests\n";
  }
  std::printf("icd_collision_overrun: load average at start %s (/proc/loadavg)\n",
              icd::experiments::load_average().c_str());
  // Workload: two deep octree trees over overlapping icospheres: a full
  // traversal takes longer than the largest budget.
  std::printf("building trees...\n");
  const Object a = icosphere_object(6, 1.0, {0, 0, 0}, 9);
  const Object b = icosphere_object(6, 1.0, {0.01, 0.005, 0.0}, 9);
  CollisionResult result;
  {
    const auto t0 = Clock::now();
    collide(a.tree, b.tree, CollisionRequest{}, result);
    std::printf(
        "trees: %d and %d spheres; full fast traversal: %lld tests, %zu leaf pairs, %.1f ms\n",
        a.tree.num_nodes(), b.tree.num_nodes(), (long long)result.tests, result.colliding.size(),
        1e3 * seconds_since(t0));
  }
  // Costs measured in this run.
  {
    const int n = 2000000;
    auto t0 = Clock::now();
    Clock::rep sink = 0;
    for (int i = 0; i < n; ++i) sink += Clock::now().time_since_epoch().count();
    const double clock_ns = 1e9 * seconds_since(t0) / n;
    std::printf("steady_clock::now(): %.1f ns per read (sink %lld)\n", clock_ns,
                (long long)(sink & 1));
  }

  std::vector<Config> configs;
  configs.push_back(
      {"paper Fig.7 literal, clock every test", CollisionRequest::paper_reference(1)});
  {
    CollisionRequest r;
    r.clock_check_interval = 16;
    configs.push_back({"fast path, steady_clock every 16", r});
    r.clock = ClockSource::CycleCounter;
    configs.push_back({"fast path, rdtsc every 16", r});
    r.clock = ClockSource::SteadyClock;
    r.clock_check_interval = 1;
    configs.push_back({"fast path, steady_clock every test", r});
  }
  const std::vector<double> budgets{10e-6, 100e-6, 1e-3, 10e-3, 100e-3};

  Floor floor;
  floor.budgets = budgets;
  // Stopped and joined on every way out (jthread), an exception included.
  std::jthread floor_thread([&](const std::stop_token& stop) { floor.run(stop); });
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(0.0, 20e-6);
  // Warm up the result buffers and calibrations.
  for (const Config& c : configs) {
    CollisionRequest r = c.request;
    r.budget_seconds = 0.1;
    collide(a.tree, b.tree, r, result);
  }
  std::printf("\n%-38s %8s %7s %6s %6s %8s %8s %6s %8s %8s %8s %9s %9s\n", "configuration",
              "budget", "queries", "compl", "early", "early50", "earlymax", "over",
              "over p50", "over p99", "p99.9", "over max", "tests p50");
  std::printf("%-38s %8s %7s %6s %6s %8s %8s %6s %8s %8s %8s %9s %9s\n", "", "", "", "n", "n",
              "us", "us", "n", "us", "us", "us", "us", "");
  for (const Config& c : configs) {
    for (std::size_t bi = 0; bi < budgets.size(); ++bi) {
      const double budget = budgets[bi];
      floor.bin = static_cast<int>(bi);
      CollisionRequest r = c.request;
      r.budget_seconds = budget;
      std::vector<double> over, early, tests, early_reserve;
      long long completed = 0;
      const auto t_cfg = Clock::now();
      for (long long q = 0; q < max_queries && seconds_since(t_cfg) < max_seconds; ++q) {
        spin_for(jitter(rng));  // random start: do not lock onto periodic host ticks
        const double cost = finish_cost_per_pair();  // what this query reserves per pending pair
        const auto t0 = Clock::now();
        collide(a.tree, b.tree, r, result);
        const double used = seconds_since(t0);
        if (!result.interrupted) {
          ++completed;
        } else if (used < budget) {
          early.push_back(budget - used);
          early_reserve.push_back(cost * static_cast<double>(result.untested.size()));
        } else
          over.push_back(used - budget);
        tests.push_back(static_cast<double>(result.tests));
      }
      const double n = static_cast<double>(tests.size());
      std::printf("%-38s %6.0fus %7.0f %6lld %6zu %8.2f %8.2f %6zu %8.2f %8.2f %8.2f %9.1f %9.0f\n",
                  c.name.c_str(), budget * 1e6, n, completed, early.size(),
                  1e6 * quantile(early, 0.5), 1e6 * quantile(early, 1.0), over.size(),
                  1e6 * quantile(over, 0.5), 1e6 * quantile(over, 0.99),
                  1e6 * quantile(over, 0.999), 1e6 * quantile(over, 1.0), median(tests));
      if (!early.empty())
        std::printf("%-38s %8s early stops: reserve p50 %.2f us (learnt %.3f ns/pair, calibrated "
                    "%.3f ns/pair after this budget)\n",
                    "", "", 1e6 * quantile(early_reserve, 0.5), 1e9 * finish_cost_per_pair(),
                    1e9 * calibrated_finish_cost_per_pair());
      std::fflush(stdout);
      if (want_csv)
        csv << '"' << c.name << "\"," << budget << ',' << n << ',' << completed << ','
            << early.size() << ',' << 1e6 * quantile(early, 0.5) << ',' << 1e6 * quantile(early, 1.0)
            << ',' << over.size() << ',' << 1e6 * quantile(over, 0.5) << ','
            << 1e6 * quantile(over, 0.99) << ',' << 1e6 * quantile(over, 0.999) << ','
            << 1e6 * quantile(over, 1.0) << ',' << median(tests) << '\n';
    }
  }
  floor.bin = -1;
  floor_thread.request_stop();
  floor_thread.join();
  std::printf(
      "\nfloor (other thread, same run, %.1f s): lateness past deadlines of the same length, per "
      "budget:\n",
      floor.spun);
  std::printf("%9s %9s %9s %9s %9s %9s\n", "budget", "deadlines", "p50 us", "p99 us", "p99.9 us",
              "max us");
  for (std::size_t bi = 0; bi < budgets.size(); ++bi) {
    const auto& l = floor.lateness[bi];
    std::printf("%8.0fus %9zu %9.2f %9.2f %9.2f %9.1f\n", budgets[bi] * 1e6, l.size(),
                1e6 * quantile(l, 0.5), 1e6 * quantile(l, 0.99), 1e6 * quantile(l, 0.999),
                1e6 * quantile(l, 1.0));
    if (want_csv)
      csv << "floor," << budgets[bi] << ',' << l.size() << ",0,0,,," << l.size() << ','
          << 1e6 * quantile(l, 0.5) << ',' << 1e6 * quantile(l, 0.99) << ',' << 1e6 * quantile(l, 0.999) << ','
          << 1e6 * quantile(l, 1.0) << ",0\n";
  }
  std::printf(
      "floor: %zu clock gaps > 1 us (%.0f per second), gap p50 %.1f us, p99 %.1f us, max %.1f us\n",
      floor.gaps.size(), floor.gaps.size() / floor.spun, 1e6 * quantile(floor.gaps, 0.5),
      1e6 * quantile(floor.gaps, 0.99), 1e6 * quantile(floor.gaps, 1.0));
  std::printf("load average at end %s\n", icd::experiments::load_average().c_str());
  if (want_csv) icd::write_file_atomically(csv_path, csv.str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return icd::experiments::guarded_main("icd_collision_overrun", run, argc, argv);
}
