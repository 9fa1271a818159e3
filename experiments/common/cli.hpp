#pragma once
/// The command line of every icd program, on CLI11 (libcli11-dev): options
/// bound to variables, flags and positional arguments, `--help` (usage on
/// stdout, exit 0, nothing run), `--version` ("icd <version>", exit 0) and one
/// error path: an unknown option, a missing value or required argument, an
/// extra argument, a malformed number ("12x", "", "nan") or a value out of its
/// range is reported on stderr as
///   <program>: <what is wrong> (see --help)
/// and the program exits with status 2 before doing anything.
///
///   Cli cli("fig9", "Writes DIR/manifest.csv.");
///   cli.path("--out", out, "DIR", "output folder").integer("--after", after, "N", "frames", 0);
///   if (const auto status = cli.parse(argc, argv)) return *status;
///
/// Values are converted after the whole line is read: `--help` or
/// `--version` anywhere applies nothing; a later value of an option replaces
/// an earlier one, except where a custom option's handler accumulates.
/// CLI11 stays out of this header (experiments/common/cli.cpp): it is
/// compiled once, not in every program.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <system_error>
#include <type_traits>
#include <utility>
#include <vector>

#include <icd/config.hpp>

#include "experiments/common/process_exit.hpp"

namespace icd::experiments {

class Cli {
 public:
  /// `program`: the name in messages and the usage; `footer`: lines printed
  /// after the option list (what it does, defaults, outputs; may be empty).
  explicit Cli(std::string program, std::string footer = {});
  ~Cli();
  Cli(const Cli&) = delete;
  Cli& operator=(const Cli&) = delete;

  /// A positional argument (bound in the order declared; they may stand
  /// before, between or after the options). A required one missing is an
  /// error; an optional one keeps its default. More words than arguments is
  /// an error.
  Cli& argument(const std::string& name, const std::string& help, bool required,
                std::function<void(const std::string&)> apply);

  /// A positional argument naming a file or folder.
  Cli& argument(const std::string& name, std::filesystem::path& target, const std::string& help,
                bool required) {
    return argument(name, help, required, [&target](const std::string& v) { target = v; });
  }

  /// Positional arguments taking all the remaining words (after the single
  /// ones declared before), appended to `target` in order.
  Cli& arguments(const std::string& name, std::vector<std::filesystem::path>& target,
                 const std::string& help, bool required);

  /// Any text.
  Cli& text(const std::string& name, std::string& target, const std::string& value_name,
            const std::string& help) {
    return add(name, value_name, help, [&target](const std::string& v) { target = v; });
  }

  /// A file or folder path (not checked here: the program opens it).
  Cli& path(const std::string& name, std::filesystem::path& target, const std::string& value_name,
            const std::string& help) {
    return add(name, value_name, help, [&target](const std::string& v) { target = v; });
  }

  /// A whole number in [min, max].
  template <class Int>
  Cli& integer(const std::string& name, Int& target, const std::string& value_name,
               const std::string& help, Int min = std::numeric_limits<Int>::min(),
               Int max = std::numeric_limits<Int>::max()) {
    return add(name, value_name, help, [&target, min, max](const std::string& v) {
      target = parse_integer<Int>(v, min, max);
    });
  }

  /// A finite number in [min, max].
  Cli& real(const std::string& name, double& target, const std::string& value_name,
            const std::string& help, double min = -std::numeric_limits<double>::max(),
            double max = std::numeric_limits<double>::max()) {
    return add(name, value_name, help,
               [&target, min, max](const std::string& v) { target = parse_real(v, min, max); });
  }

  /// A yes/no option written 0 or 1.
  Cli& boolean(const std::string& name, bool& target, const std::string& help) {
    return add(name, "0|1", help,
               [&target](const std::string& v) { target = parse_integer<int>(v, 0, 1) != 0; });
  }

  /// A switch without a value: sets `target` to true.
  Cli& flag(const std::string& name, bool& target, const std::string& help);

  /// An option whose value `apply` interprets (called once per occurrence,
  /// in order); it throws std::invalid_argument with the reason when the
  /// value is not acceptable.
  Cli& custom(const std::string& name, const std::string& value_name, const std::string& help,
              std::function<void(const std::string&)> apply) {
    return add(name, value_name, help, std::move(apply));
  }

  /// The scene overrides every program that reads a scene takes:
  /// `--set KEY=VALUE` (repeatable, applied in order; see runner::load_scene).
  Cli& scene_overrides(std::vector<std::string>& target) {
    return custom("--set", "KEY=VALUE",
                  "override a scene field (repeatable; KEY dotted, array indices as numbers, e.g. "
                  "objects.1.material.young=2e5; VALUE JSON, else a string)",
                  [&target](const std::string& v) { target.push_back(v); });
  }

  /// `v` as a whole number in [min, max] (all of it: "12x" is not 12);
  /// throws std::invalid_argument naming what is wrong.
  template <class Int>
  static Int parse_integer(const std::string& v, Int min = std::numeric_limits<Int>::min(),
                           Int max = std::numeric_limits<Int>::max()) {
    static_assert(std::is_integral_v<Int>, "parse_integer() reads whole numbers");
    Int value{};
    const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), value);
    if (ec == std::errc::result_out_of_range || (ec == std::errc() && (value < min || value > max)))
      throw std::invalid_argument("must be in [" + std::to_string(min) + ", " +
                                  std::to_string(max) + "], got '" + v + "'");
    if (ec != std::errc() || end != v.data() + v.size())
      throw std::invalid_argument("expects a whole number, got '" + v + "'");
    return value;
  }

  /// `v` as a finite number in [min, max]; throws std::invalid_argument
  /// naming what is wrong (for custom options and comma-separated lists).
  static double parse_real(const std::string& v, double min = -std::numeric_limits<double>::max(),
                           double max = std::numeric_limits<double>::max());

  /// What the command line `args` (argv[1 ..]) asks for.
  enum class Outcome { Run, Help, Version };

  /// Reads `args` and applies the values to their variables; throws
  /// std::invalid_argument with "what is wrong" (naming the option or
  /// argument) on any error. After Help or Version nothing was applied.
  Outcome apply(const std::vector<std::string>& args);

  /// apply() on the command line: std::nullopt to go on, or the exit status
  /// the program should return (0 after --help or --version, with the text
  /// on stdout; 2 after an error, with the one-line message on stderr).
  std::optional<int> parse(int argc, char** argv);

  /// The help text (description, usage line, options, footer).
  std::string usage() const;

  /// "icd <version>\n".
  static std::string version_line() { return "icd " ICD_VERSION_STRING "\n"; }

  /// Prints the one error wording on stderr and returns 2.
  /// Control bytes in `what` (from the command line) are written as \xNN.
  static int fail(const std::string& program, const std::string& what);

 private:
  struct Impl;  // the CLI11 app and the declared options

  Cli& add(const std::string& name, const std::string& value_name, const std::string& help,
           std::function<void(const std::string&)> apply);

  std::string m_program;
  std::unique_ptr<Impl> m_impl;
};

/// The command line of a Google Benchmark program: `--help` prints this
/// program's description and the benchmark flags it takes, `--version` the
/// version, both without running anything; call before
/// benchmark::Initialize(), then benchmark_leftover() after it. Under a memory
/// limit the process ends without the libraries' shutdown (process_exit.hpp).
inline std::optional<int> benchmark_preamble(int argc, char** argv, const std::string& program,
                                             const std::string& description) {
  exit_without_library_shutdown_under_memory_limits();
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") {
      std::printf(
          "%s\nUsage: %s [--benchmark_filter=REGEX] [--benchmark_repetitions=N] "
          "[--benchmark_format=console|json|csv] [--benchmark_out=FILE] [other --benchmark_* "
          "flags of Google Benchmark]\n\nOptions:\n"
          "  -h,--help                   print this help and exit\n"
          "  --version                   print the version (icd %s) and exit\n"
          "  --benchmark_list_tests      list the benchmarks and exit\n"
          "  --benchmark_filter=REGEX    run only the benchmarks matching REGEX\n"
          "  --benchmark_min_time=S      minimum time per benchmark\n"
          "  --benchmark_repetitions=N   repetitions of each benchmark\n"
          "  --benchmark_out=FILE        also write the results to FILE\n",
          description.c_str(), program.c_str(), ICD_VERSION_STRING);
      return 0;
    }
    if (a == "--version") {
      std::fputs(Cli::version_line().c_str(), stdout);
      return 0;
    }
  }
  return std::nullopt;
}

/// After benchmark::Initialize() removed the flags it knows: anything left
/// is an error in the one wording (status 2), else std::nullopt.
inline std::optional<int> benchmark_leftover(int argc, char** argv, const std::string& program) {
  if (argc <= 1) return std::nullopt;
  const std::string a = argv[1];
  return Cli::fail(program, !a.empty() && a[0] == '-' ? "unknown option '" + a + "'"
                                                      : "unexpected argument '" + a + "'");
}

}  // namespace icd::experiments
