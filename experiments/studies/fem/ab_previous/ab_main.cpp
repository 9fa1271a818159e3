// Frame-interleaved A/B of two fem code versions in one process (run_ab.sh):
// RK4 and symplectic Euler of the previous version (old) and of the working
// tree (new) on the fem_realtime scene, 60 frames of 1/60 s per repetition, a
// fresh Simulator each; the four advance frame by frame in turn, so that load
// changes on a shared machine hit all alike. Per configuration: the sum over
// the frames of each frame's median process CPU time over the repetitions
// (and without the first frame, whose cold omega_max estimate a long run pays
// once), the sub-steps and the lowest z at the end (equal for equal
// trajectories).
// Usage: ab_main [mesh: 0 bar, 1 block] [repetitions] [check interval]
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <string>
#include <vector>

void* make_sim_old(int, int, int);
int advance_old(void*);
double lowest_z_old(void*);
void free_sim_old(void*);
void* make_sim_new(int, int, int);
int advance_new(void*);
double lowest_z_new(void*);
void free_sim_new(void*);

namespace {

double cpu_seconds() {
  timespec t;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

std::string load_average() {
  std::ifstream in("/proc/loadavg");
  std::string a, b, c;
  in >> a >> b >> c;
  return in ? a + " " + b + " " + c : "unknown";
}

}  // namespace

int main(int argc, char** argv) {
  const int mesh = argc > 1 ? std::atoi(argv[1]) : 0;
  const int reps = argc > 2 ? std::atoi(argv[2]) : 11;
  const int check = argc > 3 ? std::atoi(argv[3]) : 1;
  std::printf("%s, check interval %d, %d repetitions, load average before: %s\n",
              mesh ? "block" : "bar", check, reps, load_average().c_str());
  const char* names[4] = {"old rk4", "old symplectic_euler", "new rk4", "new symplectic_euler"};
  std::vector<std::vector<double>> frames[4];
  for (auto& f : frames) f.assign(60, {});
  long steps[4] = {0, 0, 0, 0};
  double low[4] = {0, 0, 0, 0};
  for (int r = 0; r < reps; ++r) {
    void* sims[4] = {make_sim_old(0, mesh, check), make_sim_old(1, mesh, check),
                     make_sim_new(0, mesh, check), make_sim_new(1, mesh, check)};
    for (int f = 0; f < 60; ++f)
      for (int k = 0; k < 4; ++k) {
        const double c0 = cpu_seconds();
        const int n = k < 2 ? advance_old(sims[k]) : advance_new(sims[k]);
        frames[k][f].push_back(cpu_seconds() - c0);
        if (r == 0) steps[k] += n;
      }
    for (int k = 0; k < 4; ++k) {
      low[k] = k < 2 ? lowest_z_old(sims[k]) : lowest_z_new(sims[k]);
      if (k < 2)
        free_sim_old(sims[k]);
      else
        free_sim_new(sims[k]);
    }
  }
  double total[4], steady[4];
  for (int k = 0; k < 4; ++k) {
    total[k] = steady[k] = 0;
    for (int f = 0; f < 60; ++f) {
      const double m = median(frames[k][f]);
      total[k] += m;
      if (f > 0) steady[k] += m;
    }
    steady[k] *= 60.0 / 59.0;
    std::printf(
        "%-21s %.4f s CPU per simulated s (without the first frame %.4f s), %ld sub-steps, lowest "
        "z %.9f m\n",
        names[k], total[k], steady[k], steps[k], low[k]);
  }
  std::printf(
      "symplectic Euler / RK4: old %.3fx (without the first frame %.3fx), new %.3fx (%.3fx); new "
      "vs old: RK4 "
      "%.3fx, symplectic Euler %.3fx faster\n",
      total[0] / total[1], steady[0] / steady[1], total[2] / total[3], steady[2] / steady[3],
      total[0] / total[2], total[1] / total[3]);
  std::printf("load average after: %s\n", load_average().c_str());
  return 0;
}
