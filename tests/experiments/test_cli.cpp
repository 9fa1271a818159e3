// The programs' command line (experiments/common/cli.hpp, on CLI11): values
// land in their variables, --help and --version apply nothing, and every
// kind of bad command line is an error that names the option.
#include <gtest/gtest.h>

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "experiments/common/cli.hpp"

namespace {

using icd::experiments::Cli;
using Outcome = Cli::Outcome;

struct Values {
  std::filesystem::path out = "default";
  std::string budgets = "1e-3";
  int reps = 5;
  long long queries = 10;
  double seconds = 1.5;
  bool quick = false;
  bool octree = true;
  std::vector<double> list;
};

// Declares the options of `v` on `cli`.
void declare(Cli& cli, Values& v) {
  cli.path("--out", v.out, "DIR", "output folder")
      .text("--budgets", v.budgets, "a,b", "critical times")
      .integer("--reps", v.reps, "N", "repetitions", 1, 100)
      .integer("--queries", v.queries, "N", "queries", 0LL)
      .real("--max-seconds", v.seconds, "S", "time limit", 0.0)
      .flag("--quick", v.quick, "extreme cases only")
      .boolean("--octree", v.octree, "also the octree baseline")
      .custom("--item", "X", "appended to a list",
              [&v](const std::string& s) { v.list.push_back(Cli::parse_real(s, 0.0)); });
}

// apply(args) on a fresh command line with the options of `v`.
Outcome apply(Values& v, const std::vector<std::string>& args) {
  Cli cli("prog", "Defaults: reps 5.");
  declare(cli, v);
  return cli.apply(args);
}

// The message of the std::invalid_argument that apply() throws ("" if none).
std::string error_of(const std::vector<std::string>& args) {
  Values v;
  try {
    apply(v, args);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(Cli, AppliesEveryKindOfOptionAndKeepsDefaults) {
  Values v;
  EXPECT_EQ(apply(v, {}), Outcome::Run);
  EXPECT_EQ(v.out, "default");
  EXPECT_EQ(v.reps, 5);
  EXPECT_EQ(apply(v, {"--out", "dir/x", "--reps", "7", "--queries", "123456789012",
                             "--max-seconds", "2.5e-1", "--quick", "--budgets", "1e-4,1", "--item",
                             "3", "--item", "0.5", "--reps", "8", "--octree", "0"}),
            Outcome::Run);
  EXPECT_EQ(v.out, "dir/x");
  EXPECT_EQ(v.reps, 8);  // the later value wins
  EXPECT_EQ(v.queries, 123456789012LL);
  EXPECT_DOUBLE_EQ(v.seconds, 0.25);
  EXPECT_TRUE(v.quick);
  EXPECT_EQ(v.budgets, "1e-4,1");
  EXPECT_EQ(v.list, (std::vector<double>{3.0, 0.5}));
  EXPECT_FALSE(v.octree);
  EXPECT_EQ(apply(v, {"--octree=1"}), Outcome::Run);
  EXPECT_TRUE(v.octree);
}

TEST(Cli, HelpAndVersionApplyNothingEvenBesideABadValue) {
  Values v;
  EXPECT_EQ(apply(v, {"--reps", "2", "--help", "--reps", "3"}), Outcome::Help);
  EXPECT_EQ(v.reps, 5);
  EXPECT_EQ(apply(v, {"-h"}), Outcome::Help);
  EXPECT_EQ(apply(v, {"--reps", "0", "--help"}), Outcome::Help);
  EXPECT_EQ(apply(v, {"--frobnicate", "--version"}), Outcome::Version);
  EXPECT_EQ(v.reps, 5);
  EXPECT_EQ(Cli::version_line(), std::string("icd ") + ICD_VERSION_STRING + "\n");
  // After "--" the words are arguments, not options.
  EXPECT_NE(error_of({"--", "--help"}), "");
}

TEST(Cli, EveryBadCommandLineNamesTheOptionAndTheProblem) {
  struct Case {
    std::vector<std::string> args;
    std::string expected;  // a part of the message
  };
  const std::vector<Case> cases = {
      {{"--frobnicate"}, "unknown option '--frobnicate'"},
      {{"out"}, "unexpected argument 'out'"},
      {{"-"}, "unexpected argument '-'"},
      {{"--reps"}, "--reps needs a value"},
      {{"--reps", "12x"}, "--reps expects a whole number, got '12x'"},
      {{"--reps", ""}, "--reps expects a whole number, got ''"},
      {{"--reps", "2.5"}, "--reps expects a whole number"},
      {{"--reps", "0"}, "--reps must be in [1, 100], got '0'"},
      {{"--reps", "101"}, "--reps must be in [1, 100]"},
      {{"--reps", "99999999999999999999"}, "--reps must be in [1, 100]"},
      {{"--queries", "-1"}, "--queries must be in [0, "},
      {{"--max-seconds", "nan"}, "--max-seconds expects a finite number, got 'nan'"},
      {{"--max-seconds", "inf"}, "--max-seconds expects a finite number"},
      {{"--max-seconds", "1s"}, "--max-seconds expects a finite number, got '1s'"},
      {{"--max-seconds", "-2"}, "--max-seconds must be in [0, "},
      {{"--item", "x"}, "--item expects a finite number, got 'x'"},
      {{"--octree", "2"}, "--octree must be in [0, 1], got '2'"},
      {{"--octree", "yes"}, "--octree expects a whole number, got 'yes'"},
      {{"--item", "-1"}, "--item must be in [0, "},
  };
  for (const Case& c : cases) {
    const std::string message = error_of(c.args);
    EXPECT_NE(message.find(c.expected), std::string::npos)
        << "args " << ::testing::PrintToString(c.args) << ": got '" << message << "'";
  }
}

TEST(Cli, PositionalArgumentsBindInOrderAnywhereAmongTheOptions) {
  std::filesystem::path dir;
  int threads = 1;
  bool quick = false;
  auto declare_positional = [&](Cli& cli) {
    cli.argument("DIR", dir, "output folder", true)
        .argument("THREADS", "worker threads", false,
                  [&threads](const std::string& v) { threads = Cli::parse_integer<int>(v, 1, 64); })
        .flag("--quick", quick, "quick");
  };
  auto apply_positional = [&](const std::vector<std::string>& args) {
    Cli cli("prog");
    declare_positional(cli);
    return cli.apply(args);
  };
  EXPECT_EQ(apply_positional({"--quick", "out/a", "--quick", "4"}), Outcome::Run);
  EXPECT_EQ(dir, "out/a");
  EXPECT_EQ(threads, 4);
  EXPECT_TRUE(quick);
  threads = 1;
  EXPECT_EQ(apply_positional({"out/b"}), Outcome::Run);  // the optional one keeps its default
  EXPECT_EQ(dir, "out/b");
  EXPECT_EQ(threads, 1);
  auto error = [&](const std::vector<std::string>& args) -> std::string {
    try {
      apply_positional(args);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_EQ(error({}), "missing DIR");
  EXPECT_EQ(error({"--quick"}), "missing DIR");
  EXPECT_EQ(error({"--slow"}), "unknown option '--slow'");  // before the missing DIR
  EXPECT_EQ(error({"d", "0"}), "THREADS must be in [1, 64], got '0'");
  EXPECT_EQ(error({"d", "2x"}), "THREADS expects a whole number, got '2x'");
  EXPECT_EQ(error({"d", "2", "extra"}), "unexpected argument 'extra'");
  EXPECT_EQ(error({"d", "--slow"}), "unknown option '--slow'");
  EXPECT_EQ(apply_positional({"--help"}), Outcome::Help);  // help needs no DIR
  Cli cli("prog");
  declare_positional(cli);
  const std::string usage = cli.usage();
  EXPECT_NE(usage.find("Usage: prog [OPTIONS] DIR [THREADS]"), std::string::npos) << usage;
  EXPECT_NE(usage.find("  THREADS"), std::string::npos) << usage;
}

TEST(Cli, ListArgumentTakesEveryRemainingWordInOrder) {
  std::vector<std::filesystem::path> files;
  bool quick = false;
  auto apply_list = [&](const std::vector<std::string>& args) {
    files.clear();
    Cli cli("prog");
    cli.arguments("FILE", files, "input files", true).flag("--quick", quick, "quick");
    return cli.apply(args);
  };
  EXPECT_EQ(apply_list({"a.off"}), Outcome::Run);
  EXPECT_EQ(files, (std::vector<std::filesystem::path>{"a.off"}));
  EXPECT_EQ(apply_list({"a.off", "--quick", "b.obj", "c.ply"}), Outcome::Run);
  EXPECT_EQ(files, (std::vector<std::filesystem::path>{"a.off", "b.obj", "c.ply"}));
  EXPECT_TRUE(quick);
  try {
    apply_list({"--quick"});
    ADD_FAILURE() << "a required list with no word must be refused";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "missing FILE");
  }
}

TEST(Cli, UsageListsEveryOptionAndTheSummary) {
  Values v;
  Cli cli("prog", "Defaults: reps 5.");
  declare(cli, v);
  const std::string usage = cli.usage();
  for (const char* part : {"Usage: prog", "--out DIR", "--reps N", "--quick", "--version",
                           "critical times", "extreme cases only", "Defaults: reps 5."})
    EXPECT_NE(usage.find(part), std::string::npos) << part << " missing from\n" << usage;
}

}  // namespace
