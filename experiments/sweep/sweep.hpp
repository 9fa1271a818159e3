#pragma once
/// icd-sweep's core, independent of the backend: reading a sweep file,
/// expanding its cases deterministically, running one case as a child process
/// (no shell, limits, atomic case folder) and gathering the case results into
/// one CSV and a markdown section. The backends (local pool, MPI, Slurm array)
/// only decide WHICH process runs a case; all of them call run_case() and
/// gather(), so their CSVs are byte-identical. See experiments/sweep/README.md.
#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace icd::sweep {

/// Per-case limits (0 = none).
struct Limits {
  double wall_seconds = 0;      ///< the case's process group is killed (SIGKILL) after this
  double cpu_seconds = 0;       ///< RLIMIT_CPU
  std::uint64_t memory_bytes = 0;  ///< RLIMIT_AS
};

/// What to read from a finished case.
struct Collect {
  std::string kind;                  ///< "csv", "json", "log" or "" (status only)
  std::string file;                  ///< csv/json: the file inside the case's {out} folder
  std::vector<std::string> columns;  ///< csv: columns kept (empty = all); json: JSON pointers
  std::string rows = "all";          ///< csv: "all" or "last"
  /// log: (column, ECMAScript regex) pairs matched against the case's stdout
  /// then stderr; the column gets the first group of the first match.
  std::vector<std::pair<std::string, std::string>> patterns;
};

/// One case: its parameters (name, value as text, in the sweep file's order)
/// and the program's argument list (placeholders expanded except {out}).
struct Case {
  std::string id;      ///< 16 hex digits: hash of program, arguments, parameters, input checksums
  std::size_t index = 0;  ///< position in the expanded order (for --case K)
  std::vector<std::pair<std::string, std::string>> params;
  std::vector<std::string> args;  ///< without argv[0]; "{out}" still a placeholder
  /// What id hashes, plus the collection settings (stored in the marker;
  /// a finished case is skipped only when its marker holds the same key).
  std::string key;
};

/// A sweep file, expanded.
struct Plan {
  std::string name;
  std::string title;
  std::filesystem::path sweep_file;
  std::filesystem::path program;  ///< absolute path in the build's bin/
  std::vector<std::string> param_names;  ///< CSV parameter columns, in order
  std::vector<Case> cases;
  Collect collect;
  Limits limits;
  std::vector<int> accept_exit;  ///< exit statuses counted as success (default {0})
  bool keep_outputs = true;      ///< false: the case's {out} is removed after collection
  /// Commands run once, one after the other, before any case (e.g. filling
  /// the asset cache, which is not safe for concurrent first use): program
  /// paths in bin/ and their arguments ("{out}" = <out>/setup/<k>).
  std::vector<std::vector<std::string>> setup;
};

/// Runs the plan's setup commands (skipped when they succeeded before with the
/// same arguments). Throws icd::InputError naming the command on a failure.
void run_setup(const Plan& plan, const std::filesystem::path& out);

/// Reads and expands a sweep file. `bin_dir`: where programs are looked up.
/// Throws icd::InputError naming the file and field on any problem.
Plan load_plan(const std::filesystem::path& sweep_file, const std::filesystem::path& bin_dir);

/// The result of one case, as stored in its marker (<out>/cases/<id>/result.json).
struct CaseResult {
  std::string id;
  std::string status;  ///< "ok", "failed", "timeout", "killed", "missing"
  int exit_status = -1;
  int signal = 0;
  std::string message;
  double wall_seconds = 0;  ///< not in the CSV (differs between runs)
  std::vector<std::string> columns;             ///< collected column names
  std::vector<std::vector<std::string>> rows;   ///< collected rows
  std::string key;
  std::string to_json() const;
  static CaseResult from_json(const std::string& text);
};

/// The case folder <out>/cases/<id>.
std::filesystem::path case_dir(const std::filesystem::path& out, const Case& c);

/// The stored result of a case when its marker exists and matches the case's
/// key and it succeeded (finished cases are skipped on re-run; failed ones run again).
bool finished(const std::filesystem::path& out, const Case& c, CaseResult* result = nullptr);

/// Runs one case: in <out>/cases/<id>.tmp/ (out/, stdout.txt, stderr.txt,
/// result.json), then renames that folder to <out>/cases/<id> (replacing a
/// previous failed run). Never throws for a failing case: the failure is the result.
CaseResult run_case(const Plan& plan, const Case& c, const std::filesystem::path& out);

/// Writes <out>/results.csv (rows sorted by case id) and <out>/results.md,
/// atomically. `results` may be in any order; a case without a result is
/// recorded as "missing". Returns the number of cases not ok.
int gather(const Plan& plan, std::vector<CaseResult> results, const std::filesystem::path& out);

/// Reads every case's marker (for --gather and resume).
std::vector<CaseResult> read_results(const Plan& plan, const std::filesystem::path& out);

/// Kills every running case's process group (from a signal handler's flag).
void request_stop();
bool stop_requested();

/// 64-bit FNV-1a of bytes, as 16 hex digits.
std::string hash_hex(std::string_view bytes);

/// `s` quoted for a POSIX shell script (single quotes).
std::string shell_quote(const std::string& s);

}  // namespace icd::sweep
