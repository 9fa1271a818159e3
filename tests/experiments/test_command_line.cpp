// The experiment programs' option parser: values land in their variables,
// and every kind of bad command line is an error that names the option.
#include <gtest/gtest.h>

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "experiments/common/command_line.hpp"

namespace {

using icd::experiments::CommandLine;

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

CommandLine make(Values& v) {
  CommandLine cli("prog", "Defaults: reps 5.");
  cli.path("--out", v.out, "DIR", "output folder")
      .text("--budgets", v.budgets, "a,b", "critical times")
      .integer("--reps", v.reps, "N", "repetitions", 1, 100)
      .integer("--queries", v.queries, "N", "queries", 0LL)
      .real("--max-seconds", v.seconds, "S", "time limit", 0.0)
      .flag("--quick", v.quick, "extreme cases only")
      .boolean("--octree", v.octree, "also the octree baseline")
      .custom("--item", "X", "appended to a list",
              [&v](const std::string& s) { v.list.push_back(CommandLine::parse_real(s, 0.0)); });
  return cli;
}

// The message of the std::invalid_argument that apply() throws ("" if none).
std::string error_of(const std::vector<std::string>& args) {
  Values v;
  try {
    make(v).apply(args);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(CommandLine, AppliesEveryKindOfOptionAndKeepsDefaults) {
  Values v;
  EXPECT_TRUE(make(v).apply({}));
  EXPECT_EQ(v.out, "default");
  EXPECT_EQ(v.reps, 5);
  EXPECT_TRUE(make(v).apply({"--out", "dir/x", "--reps", "7", "--queries", "123456789012",
                             "--max-seconds", "2.5e-1", "--quick", "--budgets", "1e-4,1", "--item",
                             "3", "--item", "0.5", "--reps", "8", "--octree", "0"}));
  EXPECT_EQ(v.out, "dir/x");
  EXPECT_EQ(v.reps, 8);  // the later value wins
  EXPECT_EQ(v.queries, 123456789012LL);
  EXPECT_DOUBLE_EQ(v.seconds, 0.25);
  EXPECT_TRUE(v.quick);
  EXPECT_EQ(v.budgets, "1e-4,1");
  EXPECT_EQ(v.list, (std::vector<double>{3.0, 0.5}));
  EXPECT_FALSE(v.octree);
  EXPECT_TRUE(make(v).apply({"--octree", "1"}));
  EXPECT_TRUE(v.octree);
}

TEST(CommandLine, HelpStopsBeforeLaterOptions) {
  Values v;
  EXPECT_FALSE(make(v).apply({"--reps", "2", "--help", "--reps", "3"}));
  EXPECT_EQ(v.reps, 2);
  EXPECT_FALSE(make(v).apply({"-h"}));
}

TEST(CommandLine, EveryBadCommandLineNamesTheOptionAndTheProblem) {
  struct Case {
    std::vector<std::string> args;
    std::string expected;  // a part of the message
  };
  const std::vector<Case> cases = {
      {{"--frobnicate"}, "unknown option '--frobnicate'"},
      {{"out"}, "unexpected argument 'out'"},
      {{"-"}, "unknown option '-'"},
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

TEST(CommandLine, PositionalArgumentsBindInOrderAnywhereAmongTheOptions) {
  std::filesystem::path dir;
  int threads = 1;
  bool quick = false;
  auto make_positional = [&] {
    CommandLine cli("prog");
    cli.argument("DIR", dir, "output folder", true)
        .argument("THREADS", "worker threads", false,
                  [&threads](const std::string& v) {
                    threads = CommandLine::parse_integer<int>(v, 1, 64);
                  })
        .flag("--quick", quick, "quick");
    return cli;
  };
  EXPECT_TRUE(make_positional().apply({"--quick", "out/a", "--quick", "4"}));
  EXPECT_EQ(dir, "out/a");
  EXPECT_EQ(threads, 4);
  EXPECT_TRUE(quick);
  threads = 1;
  EXPECT_TRUE(make_positional().apply({"out/b"}));  // the optional one keeps its default
  EXPECT_EQ(dir, "out/b");
  EXPECT_EQ(threads, 1);
  auto error = [&](const std::vector<std::string>& args) -> std::string {
    try {
      make_positional().apply(args);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_EQ(error({}), "missing DIR");
  EXPECT_EQ(error({"--quick"}), "missing DIR");
  EXPECT_EQ(error({"d", "0"}), "THREADS must be in [1, 64], got '0'");
  EXPECT_EQ(error({"d", "2x"}), "THREADS expects a whole number, got '2x'");
  EXPECT_EQ(error({"d", "2", "extra"}), "unexpected argument 'extra'");
  EXPECT_EQ(error({"d", "--slow"}), "unknown option '--slow'");
  EXPECT_FALSE(make_positional().apply({"--help"}));  // help needs no DIR
  const std::string usage = make_positional().usage();
  EXPECT_NE(usage.find("usage: prog DIR [THREADS] [--quick]"), std::string::npos) << usage;
  EXPECT_NE(usage.find("  THREADS"), std::string::npos) << usage;
}

TEST(CommandLine, UsageListsEveryOptionAndTheSummary) {
  Values v;
  const std::string usage = make(v).usage();
  for (const char* part : {"usage: prog", "[--out DIR]", "[--reps N]", "[--quick]",
                           "critical times", "extreme cases only", "Defaults: reps 5."})
    EXPECT_NE(usage.find(part), std::string::npos) << part << " missing from\n" << usage;
}

}  // namespace
