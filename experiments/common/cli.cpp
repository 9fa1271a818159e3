#include "experiments/common/cli.hpp"

#include <CLI/CLI.hpp>

namespace icd::experiments {

struct Cli::Impl {
  struct Entry {
    CLI::Option* option;
    std::string name;
    std::function<void(const std::string&)> apply;
    bool is_flag;
  };

  explicit Impl(const std::string& program) : app(std::string{}, program) {}

  CLI::App app;
  std::vector<Entry> entries;
};

namespace {

// "-o,--output" -> "--output": the name used in messages.
std::string display_name(const std::string& names) {
  const auto comma = names.rfind(',');
  return comma == std::string::npos ? names : names.substr(comma + 1);
}

std::string format(double x) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%g", x);
  return buffer;
}

}  // namespace

Cli::Cli(std::string program, std::string footer)
    : m_program(std::move(program)), m_impl(std::make_unique<Impl>(m_program)) {
  CLI::App& app = m_impl->app;
  app.allow_extras(true);  // reported by apply() in the one wording
  app.set_help_flag("-h,--help", "print this help and exit");
  app.add_flag("--version")->description("print the version (icd " ICD_VERSION_STRING ") and exit");
  if (!footer.empty()) app.footer(std::move(footer));
}

Cli::~Cli() = default;

Cli& Cli::argument(const std::string& name, const std::string& help, bool required,
                   std::function<void(const std::string&)> apply) {
  CLI::Option* o = m_impl->app.add_option(name, CLI::callback_t{}, help, false);
  o->expected(1)->type_name("");
  if (required) o->required();
  m_impl->entries.push_back({o, name, std::move(apply), false});
  return *this;
}

Cli& Cli::arguments(const std::string& name, std::vector<std::filesystem::path>& target,
                    const std::string& help, bool required) {
  CLI::Option* o = m_impl->app.add_option(name, CLI::callback_t{}, help, false);
  // Every word goes to this one option: without TakeAll, CLI11 2.1 refuses a
  // second word ("At Most 1 required but received 2").
  o->expected(-1)->type_name("")->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  if (required) o->required();
  m_impl->entries.push_back(
      {o, name, [&target](const std::string& v) { target.emplace_back(v); }, false});
  return *this;
}

Cli& Cli::flag(const std::string& name, bool& target, const std::string& help) {
  CLI::Option* o = m_impl->app.add_flag(name)->description(help);
  m_impl->entries.push_back(
      {o, display_name(name), [&target](const std::string&) { target = true; }, true});
  return *this;
}

Cli& Cli::add(const std::string& name, const std::string& value_name, const std::string& help,
              std::function<void(const std::string&)> apply) {
  CLI::Option* o = m_impl->app.add_option(name, CLI::callback_t{}, help, false);
  // Every occurrence takes exactly one value (even one that starts with '-',
  // e.g. "--after -1"); all occurrences are kept and applied in order.
  o->expected(1)->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  o->type_name(value_name.empty() ? "VALUE" : value_name);
  m_impl->entries.push_back({o, display_name(name), std::move(apply), false});
  return *this;
}

double Cli::parse_real(const std::string& v, double min, double max) {
  double value = 0;
  const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), value);
  if (ec != std::errc() || end != v.data() + v.size() || !std::isfinite(value))
    throw std::invalid_argument("expects a finite number, got '" + v + "'");
  if (value < min || value > max)
    throw std::invalid_argument("must be in [" + format(min) + ", " + format(max) + "], got '" + v +
                                "'");
  return value;
}

Cli::Outcome Cli::apply(const std::vector<std::string>& args) {
  // --help / --version win wherever they stand (before a "--"), even next
  // to a bad value: they never run anything.
  for (const std::string& a : args) {
    if (a == "--") break;
    if (a == "--help" || a == "-h") return Outcome::Help;
    if (a == "--version") return Outcome::Version;
  }
  CLI::App& app = m_impl->app;
  std::vector<std::string> reversed(args.rbegin(), args.rend());  // CLI11 reads from the back
  bool missing_required = false;
  try {
    app.clear();
    app.parse(reversed);
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
  const std::vector<std::string> extras = app.remaining();
  if (!extras.empty()) {
    const std::string& a = extras.front();
    throw std::invalid_argument(!a.empty() && a[0] == '-' && a != "-"
                                    ? "unknown option '" + a + "'"
                                    : "unexpected argument '" + a + "'");
  }
  if (missing_required) {
    for (const Impl::Entry& entry : m_impl->entries)
      if (entry.option->get_required() && entry.option->count() == 0)
        throw std::invalid_argument("missing " + entry.name);
    throw std::invalid_argument("a required argument is missing");
  }
  for (const Impl::Entry& entry : m_impl->entries) {
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

std::optional<int> Cli::parse(int argc, char** argv) {
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

std::string Cli::usage() const { return m_impl->app.help(); }

int Cli::fail(const std::string& program, const std::string& what) {
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

}  // namespace icd::experiments
