// icd-sweep: runs a parameter study described by a sweep file (JSON) as
// independent child processes, on a local process pool (default), under MPI
// (mpirun -np N icd-sweep SWEEP.json), or as a Slurm job array
// (--emit-slurm, then --case K per array task and --gather). The gathered
// results.csv is byte-identical whichever backend ran the cases.
// See experiments/sweep/README.md.
#include "experiments/common/cli.hpp"
#include "experiments/common/guarded_main.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <icd/config.hpp>
#include <icd/mesh/io/atomic_write.hpp>
#include "experiments/sweep/sweep.hpp"

#ifdef ICD_SWEEP_WITH_MPI
#include <mpi.h>
#endif

namespace fs = std::filesystem;
using namespace icd::sweep;

namespace {

extern "C" void on_signal(int) { request_stop(); }

/// Progress lines on stderr: done, running, failed, estimated time left.
class Progress {
 public:
  Progress(std::string name, std::size_t to_run, std::size_t skipped, int workers, bool quiet)
      : name_(std::move(name)), to_run_(to_run), skipped_(skipped), workers_(std::max(1, workers)),
        quiet_(quiet), start_(std::chrono::steady_clock::now()) {
    if (!quiet_)
      std::fprintf(stderr, "[icd-sweep] %s: %zu cases to run, %zu already finished (skipped), %d worker(s)\n",
                   name_.c_str(), to_run_, skipped_, workers_);
  }
  void started() {
    std::lock_guard<std::mutex> l(m_);
    ++running_;
  }
  void finished(const CaseResult& r, std::size_t index) {
    std::lock_guard<std::mutex> l(m_);
    --running_;
    ++done_;
    if (r.status != "ok") ++failed_;
    if (quiet_) return;
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const double eta = done_ ? elapsed / static_cast<double>(done_) * static_cast<double>(to_run_ - done_) : 0;
    std::fprintf(stderr, "[icd-sweep] %s: %zu/%zu done, %zu running, %zu failed, ETA %.0f s  (case %zu %s: %s%s%s)\n",
                 name_.c_str(), done_, to_run_, running_, failed_, eta, index, r.id.c_str(),
                 r.status.c_str(), r.message.empty() ? "" : ": ", r.message.c_str());
  }

 private:
  std::mutex m_;
  std::string name_;
  std::size_t to_run_, skipped_;
  int workers_;
  bool quiet_;
  std::chrono::steady_clock::time_point start_;
  std::size_t done_ = 0, running_ = 0, failed_ = 0;
};

/// The cases still to run, and the stored results of the finished ones.
void split(const Plan& plan, const fs::path& out, bool force, std::vector<std::size_t>& pending,
           std::vector<CaseResult>& results) {
  for (const Case& c : plan.cases) {
    CaseResult r;
    if (!force && finished(out, c, &r)) results.push_back(std::move(r));
    else pending.push_back(c.index);
  }
}

int report(const Plan& plan, std::vector<CaseResult> results, const fs::path& out, std::size_t ran) {
  const int not_ok = gather(plan, std::move(results), out);
  std::fprintf(stderr, "[icd-sweep] %s: %zu cases (%zu run now), %d not ok; results: %s\n",
               plan.name.c_str(), plan.cases.size(), ran, not_ok, (out / "results.csv").c_str());
  if (stop_requested()) return 130;
  return not_ok ? 1 : 0;
}

/// Backend 1: the local process pool (-j N threads, each runs one child at a time).
int run_local(const Plan& plan, const fs::path& out, int jobs, bool force, bool quiet) {
  run_setup(plan, out);
  std::vector<std::size_t> pending;
  std::vector<CaseResult> results;
  split(plan, out, force, pending, results);
  Progress progress(plan.name, pending.size(), results.size(), jobs, quiet);
  std::vector<CaseResult> fresh(pending.size());
  std::atomic<std::size_t> next{0};
  auto worker = [&] {
    for (std::size_t k; !stop_requested() && (k = next++) < pending.size();) {
      progress.started();
      fresh[k] = run_case(plan, plan.cases[pending[k]], out);
      progress.finished(fresh[k], pending[k]);
    }
  };
  std::vector<std::thread> pool;
  for (int t = 0; t < std::min<int>(jobs, static_cast<int>(pending.size())); ++t) pool.emplace_back(worker);
  for (std::thread& t : pool) t.join();
  for (CaseResult& r : fresh)
    if (!r.id.empty()) results.push_back(std::move(r));
  return report(plan, std::move(results), out, pending.size());
}

#ifdef ICD_SWEEP_WITH_MPI
/// Backend 2: MPI. Rank 0 holds the case list and hands out case indices on
/// request (dynamic: a fast worker takes more cases); workers run cases and
/// send back the result (a JSON text), which rank 0 gathers.
int run_mpi(const Plan& plan, const fs::path& out, bool force, bool quiet) {
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  if (size == 1) return run_local(plan, out, 1, force, quiet);
  constexpr int kTagResult = 1, kTagWork = 2;
  if (rank != 0) {
    std::string msg;  // first message: empty (ready)
    for (;;) {
      MPI_Send(msg.data(), static_cast<int>(msg.size()), MPI_CHAR, 0, kTagResult, MPI_COMM_WORLD);
      long long k = -1;
      MPI_Recv(&k, 1, MPI_LONG_LONG, 0, kTagWork, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
      if (k < 0) return 0;
      msg = run_case(plan, plan.cases.at(static_cast<std::size_t>(k)), out).to_json();
    }
  }
  run_setup(plan, out);  // (the workers wait for their first case meanwhile)
  std::vector<std::size_t> pending;
  std::vector<CaseResult> results;
  split(plan, out, force, pending, results);
  Progress progress(plan.name, pending.size(), results.size(), size - 1, quiet);
  std::vector<long long> busy(static_cast<std::size_t>(size), -1);
  std::size_t next = 0;
  int active = size - 1;
  while (active > 0) {
    MPI_Status st;
    MPI_Probe(MPI_ANY_SOURCE, kTagResult, MPI_COMM_WORLD, &st);
    int n = 0;
    MPI_Get_count(&st, MPI_CHAR, &n);
    std::string msg(static_cast<std::size_t>(n), '\0');
    MPI_Recv(msg.data(), n, MPI_CHAR, st.MPI_SOURCE, kTagResult, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    const auto src = static_cast<std::size_t>(st.MPI_SOURCE);
    if (!msg.empty()) {
      CaseResult r = CaseResult::from_json(msg);
      progress.finished(r, static_cast<std::size_t>(busy[src]));
      results.push_back(std::move(r));
      busy[src] = -1;
    }
    long long k = -1;
    if (next < pending.size() && !stop_requested()) {
      k = static_cast<long long>(pending[next++]);
      busy[src] = k;
      progress.started();
    } else {
      --active;
    }
    MPI_Send(&k, 1, MPI_LONG_LONG, st.MPI_SOURCE, kTagWork, MPI_COMM_WORLD);
  }
  return report(plan, std::move(results), out, pending.size());
}

bool under_mpi_launcher() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK", "MPI_LOCALNRANKS"})
    if (std::getenv(v)) return true;
  return false;
}
#endif

/// Backend 3, Slurm: the job-array script, the gather script and submit.sh.
int emit_slurm(const Plan& plan, const fs::path& out, const fs::path& self, std::size_t chunk) {
  const std::string o = out.string();
  if (o.find_first_of(" \t\n%") != std::string::npos) {
    std::fprintf(stderr, "icd-sweep: --out: %s: Slurm #SBATCH lines cannot hold spaces or '%%'\n", o.c_str());
    return 1;
  }
  const std::size_t n = plan.cases.size();
  if (chunk == 0) chunk = (n + 999) / 1000;  // Slurm's default MaxArraySize is 1001
  const std::size_t tasks = (n + chunk - 1) / chunk;
  const fs::path dir = out / "slurm";
  fs::create_directories(dir);
  std::string head = "#!/bin/bash\n# Generated by icd-sweep --emit-slurm from " + plan.sweep_file.string() +
                     "\n# " + std::to_string(n) + " cases in " + std::to_string(tasks) + " array tasks of " +
                     std::to_string(chunk) + " case(s). Submit with " + (dir / "submit.sh").string() + "\n";
  std::string array = head + "#SBATCH --job-name=icd-sweep-" + plan.name + "\n#SBATCH --array=0-" +
                      std::to_string(tasks - 1) + "\n#SBATCH --ntasks=1\n#SBATCH --cpus-per-task=1\n";
  if (plan.limits.wall_seconds > 0) {
    const long minutes = static_cast<long>(plan.limits.wall_seconds * static_cast<double>(chunk) / 60.0) + 5;
    array += "#SBATCH --time=" + std::to_string(minutes) + "\n";
  }
  if (plan.limits.memory_bytes > 0)
    array += "#SBATCH --mem=" + std::to_string(plan.limits.memory_bytes / 1048576 + 256) + "M\n";
  array += "#SBATCH --output=" + o + "/slurm/array-%A_%a.log\n";
  const std::string cmd = shell_quote(self.string()) + " " + shell_quote(plan.sweep_file.string()) +
                          " --out " + shell_quote(o);
  array += "exec " + cmd + " --case \"$SLURM_ARRAY_TASK_ID\" --chunk " + std::to_string(chunk) + "\n";
  const std::string gather_script = head + "#SBATCH --job-name=icd-sweep-" + plan.name +
                                    "-gather\n#SBATCH --ntasks=1\n#SBATCH --output=" + o +
                                    "/slurm/gather-%j.log\nexec " + cmd + " --gather\n";
  std::string submit = "#!/bin/sh\n# Submits ";
  if (!plan.setup.empty()) {
    const std::string setup_script = head + "#SBATCH --job-name=icd-sweep-" + plan.name +
                                     "-setup\n#SBATCH --ntasks=1\n#SBATCH --output=" + o +
                                     "/slurm/setup-%j.log\nexec " + cmd + " --setup\n";
    icd::write_file_atomically(dir / "setup.sbatch", setup_script);
    submit += "the setup step, then the case array when it succeeded, then the gather step after the array\n"
              "# (whatever its outcome).\nset -e\nsid=$(sbatch --parsable " + shell_quote((dir / "setup.sbatch").string()) +
              ")\njid=$(sbatch --parsable --dependency=afterok:\"${sid%%;*}\" " + shell_quote((dir / "array.sbatch").string()) + ")\n";
  } else {
    submit += "the case array, then the gather step after it (whatever its outcome).\nset -e\njid=$(sbatch --parsable " +
              shell_quote((dir / "array.sbatch").string()) + ")\n";
  }
  submit += "sbatch --dependency=afterany:\"${jid%%;*}\" " + shell_quote((dir / "gather.sbatch").string()) + "\n";
  icd::write_file_atomically(dir / "array.sbatch", array);
  icd::write_file_atomically(dir / "gather.sbatch", gather_script);
  icd::write_file_atomically(dir / "submit.sh", submit);
  fs::permissions(dir / "submit.sh", fs::perms::owner_exec | fs::perms::group_exec | fs::perms::others_exec,
                  fs::perm_options::add);
  std::printf("%s\n%s\n%s\n", (dir / "array.sbatch").c_str(), (dir / "gather.sbatch").c_str(),
              (dir / "submit.sh").c_str());
  return 0;
}

/// What the command line asks for.
struct Options {
  std::string sweep_file, out;
  int jobs = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  long long case_k = -1;
  std::size_t chunk = 0;
  bool setup_only = false, gather_only = false, emit = false, list = false, force = false,
       quiet = false, use_mpi = false;
  fs::path self;  ///< this program
};

/// Runs the mode the options select; throws on a bad sweep file or a failed
/// step.
int sweep(const Options& o) {
  const Plan plan = load_plan(o.sweep_file, o.self.parent_path());
  const fs::path out = fs::absolute(o.out.empty() ? fs::path("results/sweeps") / plan.name : fs::path(o.out));
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  if (o.list) {
    for (const Case& c : plan.cases) {
      std::printf("%zu %s", c.index, c.id.c_str());
      for (const auto& [k, v] : c.params) std::printf(" %s=%s", k.c_str(), v.c_str());
      std::printf("\n");
    }
    return 0;
  }
  if (o.emit) return emit_slurm(plan, out, o.self, o.chunk);
  if (o.setup_only) {
    run_setup(plan, out);
    return 0;
  }
  if (o.gather_only) return report(plan, read_results(plan, out), out, 0);
  if (o.case_k >= 0) {
    const std::size_t c = o.chunk ? o.chunk : 1;
    const auto first = static_cast<std::size_t>(o.case_k) * c;
    if (first >= plan.cases.size()) {
      std::fprintf(stderr, "icd-sweep: --case %lld: the sweep has %zu cases (%zu per task)\n", o.case_k,
                   plan.cases.size(), c);
      return 2;
    }
    int status = 0;
    for (std::size_t k = first; k < std::min(plan.cases.size(), first + c) && !stop_requested(); ++k) {
      CaseResult r;
      if (!o.force && finished(out, plan.cases[k], &r)) {
        std::fprintf(stderr, "[icd-sweep] case %zu %s: finished earlier (skipped)\n", k, r.id.c_str());
        continue;
      }
      r = run_case(plan, plan.cases[k], out);
      std::fprintf(stderr, "[icd-sweep] case %zu %s: %s%s%s\n", k, r.id.c_str(), r.status.c_str(),
                   r.message.empty() ? "" : ": ", r.message.c_str());
      if (r.status != "ok") status = 1;
    }
    return status;
  }
#ifdef ICD_SWEEP_WITH_MPI
  if (o.use_mpi) return run_mpi(plan, out, o.force, o.quiet);
#endif
  return run_local(plan, out, o.jobs, o.force, o.quiet);
}

/// The program; throws on a bad sweep file (main() reports it).
int run(int argc, char** argv) {
  icd::experiments::Cli cli(
      "icd-sweep",
      "Runs a parameter study (a sweep file, JSON) as independent cases and gathers one\n"
      "results.csv (sorted by case id) and results.md into --out. Finished cases are skipped\n"
      "on re-run. Backends: a local process pool (default, -j N), MPI (mpirun -np N icd-sweep\n"
      "SWEEP.json), a Slurm job array (--emit-slurm; then --case K per task, --gather).\n"
      "Exit status: 0 all cases ok, 1 a case not ok or a bad sweep file, 2 a bad command line.");
  std::filesystem::path sweep_path;
  std::string backend = "auto";
  Options o;
  cli.argument("SWEEP", sweep_path, "the sweep file (JSON; see experiments/sweep/README.md)", true)
      .text("--out", o.out, "DIR", "output folder (default results/sweeps/<sweep name>)")
      .integer("-j,--jobs", o.jobs, "N", "local backend: cases run at once (default: the CPU count)", 1, 4096)
      .custom("--backend", "auto|local|mpi", "local, mpi, or auto (mpi when started by mpirun/srun)",
              [&](const std::string& v) {
                if (v != "auto" && v != "local" && v != "mpi")
                  throw std::invalid_argument("must be auto, local or mpi, not '" + v + "'");
                backend = v;
              })
      .integer("--case", o.case_k, "K",
               "run only case K (with --chunk C: cases K*C .. K*C+C-1), no gather", 0LL, 1LL << 40)
      .integer("--chunk", o.chunk, "C",
               "cases per --case task / Slurm array task (default 1; --emit-slurm: N/1000 rounded up)",
               std::size_t{1}, std::size_t{1} << 30)
      .flag("--setup", o.setup_only, "run the sweep file's setup commands only (the Slurm setup step)")
      .flag("--gather", o.gather_only, "gather the finished cases' results only (the Slurm gather step)")
      .flag("--emit-slurm", o.emit, "write <out>/slurm/{array,gather}.sbatch and submit.sh, run nothing")
      .flag("--list", o.list, "print the expanded cases (index, id, parameters), run nothing")
      .flag("--force", o.force, "run the finished cases again too")
      .flag("--quiet", o.quiet, "no progress lines");
  if (const auto status = cli.parse(argc, argv)) return *status;
  o.sweep_file = sweep_path.string();
  const int modes = (o.case_k >= 0) + o.setup_only + o.gather_only + o.emit + o.list;
  if (modes > 1) {
    return icd::experiments::Cli::fail("icd-sweep", "--case, --setup, --gather, --emit-slurm and --list exclude each other");
  }
  o.self = fs::canonical("/proc/self/exe");
  o.use_mpi = backend == "mpi";
#ifdef ICD_SWEEP_WITH_MPI
  if (backend == "auto" && modes == 0) o.use_mpi = under_mpi_launcher();
  if (o.use_mpi) {
    MPI_Init(&argc, &argv);
    int status = 1;
    try {
      status = sweep(o);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "icd-sweep: %s\n", e.what());
      MPI_Abort(MPI_COMM_WORLD, 1);  // the other ranks may wait for this one
    }
    MPI_Finalize();
    return status;
  }
#else
  if (o.use_mpi) {
    std::fprintf(stderr, "icd-sweep: --backend mpi: this icd-sweep was built without MPI\n");
    return 2;
  }
#endif
  return sweep(o);
}

}  // namespace

int main(int argc, char** argv) { return icd::experiments::guarded_main("icd-sweep", run, argc, argv); }
