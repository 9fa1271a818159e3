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
#include <CLI/CLI.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <system_error>
#include <type_traits>
#include <utility>
#include <vector>

#include <icd/config.hpp>

namespace icd::experiments {

class Cli {
 public:
  /// `program`: the name in messages and the usage; `footer`: lines printed
  /// after the option list (what it does, defaults, outputs; may be empty).
  explicit Cli(std::string program, std::string footer = {})
      : m_program(std::move(program)), m_app(std::string{}, m_program) {
    m_app.allow_extras(true);  // reported by apply() in the one wording
    m_app.set_help_flag("-h,--help", "print this help and exit");
    m_version = m_app.add_flag("--version")->description("print the version (icd " ICD_VERSION_STRING ") and exit");
    if (!footer.empty()) m_app.footer(std::move(footer));
  }
  Cli(const Cli&) = delete;
  Cli& operator=(const Cli&) = delete;

  /// A positional argument (bound in the order declared; they may stand
  /// before, between or after the options). A required one missing is an
  /// error; an optional one keeps its default. More words than arguments is
  /// an error.
  Cli& argument(const std::string& name, const std::string& help, bool required,
                std::function<void(const std::string&)> apply) {
    CLI::Option* o = m_app.add_option(name, CLI::callback_t{}, help, false);
    o->expected(1)->type_name("");
    if (required) o->required();
    m_entries.push_back({o, name, std::move(apply), false});
    return *this;
  }

  /// A positional argument naming a file or folder.
  Cli& argument(const std::string& name, std::filesystem::path& target, const std::string& help,
                bool required) {
    return argument(name, help, required, [&target](const std::string& v) { target = v; });
  }

  /// Positional arguments taking all the remaining words (after the single
  /// ones declared before), appended to `target` in order.
  Cli& arguments(const std::string& name, std::vector<std::filesystem::path>& target,
                 const std::string& help, bool required) {
    CLI::Option* o = m_app.add_option(name, CLI::callback_t{}, help, false);
    o->expected(-1)->type_name("");
    if (required) o->required();
    m_entries.push_back({o, name, [&target](const std::string& v) { target.emplace_back(v); }, false});
    return *this;
  }

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
  Cli& flag(const std::string& name, bool& target, const std::string& help) {
    CLI::Option* o = m_app.add_flag(name)->description(help);
    m_entries.push_back({o, display_name(name), [&target](const std::string&) { target = true; }, true});
    return *this;
  }

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
                           double max = std::numeric_limits<double>::max()) {
    double value = 0;
    const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), value);
    if (ec != std::errc() || end != v.data() + v.size() || !std::isfinite(value))
      throw std::invalid_argument("expects a finite number, got '" + v + "'");
    if (value < min || value > max)
      throw std::invalid_argument("must be in [" + format(min) + ", " + format(max) + "], got '" +
                                  v + "'");
    return value;
  }

  /// What the command line `args` (argv[1 ..]) asks for.
  enum class Outcome { Run, Help, Version };

  /// Reads `args` and applies the values to their variables; throws
  /// std::invalid_argument with "what is wrong" (naming the option or
  /// argument) on any error. After Help or Version nothing was applied.
  Outcome apply(const std::vector<std::string>& args) {
    // --help / --version win wherever they stand (before a "--"), even next
    // to a bad value: they never run anything.
    for (const std::string& a : args) {
      if (a == "--") break;
      if (a == "--help" || a == "-h") return Outcome::Help;
      if (a == "--version") return Outcome::Version;
    }
    std::vector<std::string> reversed(args.rbegin(), args.rend());  // CLI11 reads from the back
    bool missing_required = false;
    try {
      m_app.clear();
      m_app.parse(reversed);
    } catch (const CLI::ArgumentMismatch& e) {
      // "--name: 1 required TEXT missing" and the like: the option's name comes first.
      const std::string what = e.what();
      const auto colon = what.find(':');
      throw std::invalid_argument(colon == std::string::npos ? what
                                                             : what.substr(0, colon) + " needs a value");
    } catch (const CLI::RequiredError&) {
      missing_required = true;  // reported after an unknown option, which explains more
    } catch (const CLI::ParseError& e) {
      throw std::invalid_argument(e.what());
    }
    const std::vector<std::string> extras = m_app.remaining();
    if (!extras.empty()) {
      const std::string& a = extras.front();
      throw std::invalid_argument(!a.empty() && a[0] == '-' && a != "-"
                                      ? "unknown option '" + a + "'"
                                      : "unexpected argument '" + a + "'");
    }
    if (missing_required) {
      for (const Entry& entry : m_entries)
        if (entry.option->get_required() && entry.option->count() == 0)
          throw std::invalid_argument("missing " + entry.name);
      throw std::invalid_argument("a required argument is missing");
    }
    for (const Entry& entry : m_entries) {
      if (entry.option->count() == 0) continue;
      if (entry.is_flag) {
        entry.apply({});
        continue;
      }
      for (const std::string& value : entry.option->results()) {
        try {
          entry.apply(value);
        } catch (const std::invalid_argument& e) {
          throw std::invalid_argument(entry.name + " " + e.what());
        }
      }
    }
    return Outcome::Run;
  }

  /// apply() on the command line: std::nullopt to go on, or the exit status
  /// the program should return (0 after --help or --version, with the text
  /// on stdout; 2 after an error, with the one-line message on stderr).
  std::optional<int> parse(int argc, char** argv) {
    std::vector<std::string> args(argv + 1, argv + argc);
    try {
      switch (apply(args)) {
        case Outcome::Run:
          return std::nullopt;
        case Outcome::Help:
          std::fputs(usage().c_str(), stdout);
          return 0;
        case Outcome::Version:
          std::fputs(version_line().c_str(), stdout);
          return 0;
      }
    } catch (const std::invalid_argument& e) {
      return fail(m_program, e.what());
    }
    return 2;
  }

  /// The help text (description, usage line, options, footer).
  std::string usage() const { return m_app.help(); }

  /// "icd <version>\n".
  static std::string version_line() { return "icd " ICD_VERSION_STRING "\n"; }

  /// Prints the one error wording on stderr and returns 2.
  /// Control bytes in `what` (from the command line) are written as \xNN.
  static int fail(const std::string& program, const std::string& what) {
    std::string text;
    for (const char c : what) {
      const auto byte = static_cast<unsigned char>(c);
      if (byte < 0x20 || byte == 0x7f) {
        char hex[8];
        std::snprintf(hex, sizeof hex, "\\x%02x", byte);
        text += hex;
      } else {
        text += c;
      }
    }
    std::fprintf(stderr, "%s: %s (see --help)\n", program.c_str(), text.c_str());
    return 2;
  }

  /// The underlying CLI11 app (for what the wrappers above do not cover).
  CLI::App& app() { return m_app; }

 private:
  struct Entry {
    CLI::Option* option;
    std::string name;
    std::function<void(const std::string&)> apply;
    bool is_flag;
  };

  Cli& add(const std::string& name, const std::string& value_name, const std::string& help,
           std::function<void(const std::string&)> apply) {
    CLI::Option* o = m_app.add_option(name, CLI::callback_t{}, help, false);
    // Every occurrence takes exactly one value (even one that starts with '-',
    // e.g. "--after -1"); all occurrences are kept and applied in order.
    o->expected(1)->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
    o->type_name(value_name.empty() ? "VALUE" : value_name);
    m_entries.push_back({o, display_name(name), std::move(apply), false});
    return *this;
  }

  // "-o,--output" -> "--output": the name used in messages.
  static std::string display_name(const std::string& names) {
    const auto comma = names.rfind(',');
    return comma == std::string::npos ? names : names.substr(comma + 1);
  }

  static std::string format(double x) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%g", x);
    return buffer;
  }

  std::string m_program;
  CLI::App m_app;
  CLI::Option* m_version = nullptr;
  std::vector<Entry> m_entries;
};

/// The command line of a Google Benchmark program: `--help` prints this
/// program's description and the benchmark flags it takes, `--version` the
/// version, both without running anything; call before
/// benchmark::Initialize(), then benchmark_leftover() after it.
inline std::optional<int> benchmark_preamble(int argc, char** argv, const std::string& program,
                                             const std::string& description) {
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
