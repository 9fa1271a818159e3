#pragma once
/// Command-line options of the experiment programs: `--name value` options
/// bound to variables, `--name` flags and positional arguments, one usage
/// text built from them, and one error path. An unknown option, a missing
/// value or required argument, an extra argument, a malformed number ("12x",
/// "", "nan") or a value out of its range is reported with the option's (or
/// argument's) name and what is wrong, followed by the usage, and the
/// program exits with status 2 before doing anything; `--help` / `-h` prints
/// the usage and exits with 0.
///
///   CommandLine cli("fig9", "Writes DIR/manifest.csv.");
///   cli.path("--out", out, "DIR", "output folder").integer("--after", after, "N", "frames", 0);
///   if (const auto status = cli.parse(argc, argv)) return *status;
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

namespace icd::experiments {

class CommandLine {
 public:
  /// `program`: the name used in messages; `summary`: lines printed after the
  /// option list (defaults, outputs; may be empty).
  explicit CommandLine(std::string program, std::string summary = {})
      : m_program(std::move(program)), m_summary(std::move(summary)) {}

  /// A positional argument: a word that does not start with '-', bound to
  /// the arguments in the order they are declared (they may stand before,
  /// between or after the options). A required one missing is an error; an
  /// optional one keeps its default. More words than arguments is an error.
  CommandLine& argument(const std::string& name, const std::string& help, bool required,
                        std::function<void(const std::string&)> apply) {
    m_arguments.push_back({name, {}, help, std::move(apply), required});
    return *this;
  }

  /// A positional argument naming a file or folder.
  CommandLine& argument(const std::string& name, std::filesystem::path& target,
                        const std::string& help, bool required) {
    return argument(name, help, required, [&target](const std::string& v) { target = v; });
  }

  /// Any text.
  CommandLine& text(const std::string& name, std::string& target, const std::string& value_name,
                    const std::string& help) {
    return add(name, value_name, help, [&target](const std::string& v) { target = v; });
  }

  /// A file or folder path (not checked here: the program opens it).
  CommandLine& path(const std::string& name, std::filesystem::path& target,
                    const std::string& value_name, const std::string& help) {
    return add(name, value_name, help, [&target](const std::string& v) { target = v; });
  }

  /// A whole number in [min, max].
  template <class Int>
  CommandLine& integer(const std::string& name, Int& target, const std::string& value_name,
                       const std::string& help, Int min = std::numeric_limits<Int>::min(),
                       Int max = std::numeric_limits<Int>::max()) {
    return add(name, value_name, help, [&target, min, max](const std::string& v) {
      target = parse_integer<Int>(v, min, max);
    });
  }

  /// A finite number in [min, max].
  CommandLine& real(const std::string& name, double& target, const std::string& value_name,
                    const std::string& help, double min = -std::numeric_limits<double>::max(),
                    double max = std::numeric_limits<double>::max()) {
    return add(name, value_name, help,
               [&target, min, max](const std::string& v) { target = parse_real(v, min, max); });
  }

  /// A yes/no option written 0 or 1.
  CommandLine& boolean(const std::string& name, bool& target, const std::string& help) {
    return add(name, "0|1", help,
               [&target](const std::string& v) { target = parse_integer<int>(v, 0, 1) != 0; });
  }

  /// A switch without a value: sets `target` to true.
  CommandLine& flag(const std::string& name, bool& target, const std::string& help) {
    m_options.push_back({name, {}, help, [&target](const std::string&) { target = true; }, false});
    return *this;
  }

  /// An option whose value `apply` interprets; it throws
  /// std::invalid_argument with the reason when the value is not acceptable.
  CommandLine& custom(const std::string& name, const std::string& value_name,
                      const std::string& help, std::function<void(const std::string&)> apply) {
    return add(name, value_name, help, std::move(apply));
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

  /// Applies argv[1 ..] in order (a later value of an option replaces an
  /// earlier one, except where the option's own handler accumulates); throws
  /// std::invalid_argument with a message naming the option on any error.
  /// Returns false when --help or -h was given (nothing after it is applied).
  bool apply(const std::vector<std::string>& args) const {
    size_t next_argument = 0;
    for (size_t i = 0; i < args.size(); ++i) {
      const std::string& a = args[i];
      if (a == "--help" || a == "-h") return false;
      if (!a.empty() && a[0] != '-' && next_argument < m_arguments.size()) {
        const Option& argument = m_arguments[next_argument++];
        try {
          argument.apply(a);
        } catch (const std::invalid_argument& e) {
          throw std::invalid_argument(argument.name + " " + e.what());
        }
        continue;
      }
      const Option* option = find(a);
      if (option == nullptr)
        throw std::invalid_argument(!a.empty() && a[0] != '-' ? "unexpected argument '" + a + "'"
                                                              : "unknown option '" + a + "'");
      if (option->value_name.empty()) {
        option->apply({});
        continue;
      }
      if (i + 1 >= args.size()) throw std::invalid_argument(a + " needs a value");
      try {
        option->apply(args[++i]);
      } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(a + " " + e.what());
      }
    }
    for (size_t k = next_argument; k < m_arguments.size(); ++k)
      if (m_arguments[k].required) throw std::invalid_argument("missing " + m_arguments[k].name);
    return true;
  }

  /// apply() on the command line: std::nullopt to go on, or the exit status
  /// the program should return (0 after --help, with the usage on stdout; 2
  /// after an error, with the message and the usage on stderr).
  std::optional<int> parse(int argc, char** argv) const {
    std::vector<std::string> args(argv + 1, argv + argc);
    try {
      if (apply(args)) return std::nullopt;
      std::fputs(usage().c_str(), stdout);
      return 0;
    } catch (const std::invalid_argument& e) {
      std::fprintf(stderr, "%s: %s\n%s", m_program.c_str(), e.what(), usage().c_str());
      return 2;
    }
  }

  /// "usage: program [--name VALUE]...", one line per option with its help,
  /// then the summary.
  std::string usage() const {
    std::string out = "usage: " + m_program;
    for (const Option& a : m_arguments) out += a.required ? " " + a.name : " [" + a.name + "]";
    const size_t indent = std::min<size_t>(out.size(), 12);
    size_t line_start = 0;
    for (const Option& o : m_options) {
      const std::string item =
          " [" + o.name + (o.value_name.empty() ? "" : " " + o.value_name) + "]";
      if (out.size() - line_start + item.size() > 80) {  // wrap the synopsis
        out += "\n";
        line_start = out.size();
        out += std::string(indent, ' ');
      }
      out += item;
    }
    out += "\n";
    for (const Option& a : m_arguments) {
      std::string left = "  " + a.name;
      if (left.size() < 28) left.resize(28, ' ');
      out += left + " " + a.help + "\n";
    }
    for (const Option& o : m_options) {
      std::string left = "  " + o.name + (o.value_name.empty() ? "" : " " + o.value_name);
      if (left.size() < 28) left.resize(28, ' ');
      out += left + " " + o.help + "\n";
    }
    if (!m_summary.empty()) out += m_summary + (m_summary.back() == '\n' ? "" : "\n");
    return out;
  }

 private:
  struct Option {
    std::string name, value_name, help;
    std::function<void(const std::string&)> apply;
    bool required = false;  // positional arguments only
  };

  CommandLine& add(const std::string& name, const std::string& value_name, const std::string& help,
                   std::function<void(const std::string&)> apply) {
    m_options.push_back(
        {name, value_name.empty() ? "VALUE" : value_name, help, std::move(apply), false});
    return *this;
  }

  const Option* find(const std::string& name) const {
    for (const Option& o : m_options)
      if (o.name == name) return &o;
    return nullptr;
  }

  static std::string format(double x) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%g", x);
    return buffer;
  }

  std::string m_program, m_summary;
  std::vector<Option> m_options, m_arguments;
};

}  // namespace icd::experiments
