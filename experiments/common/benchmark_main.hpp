#pragma once
/// ICD_BENCHMARK_MAIN(program, description): the main() of a Google
/// Benchmark program with the command line of every icd program: `--help`
/// and `--version` answer without running anything, the --benchmark_* flags
/// go to Google Benchmark, anything else is refused in the one wording
/// "<program>: unknown option '...' (see --help)" with exit status 2.
#include <benchmark/benchmark.h>

#include "experiments/common/cli.hpp"

#define ICD_BENCHMARK_MAIN(program, description)                                          \
  int main(int argc, char** argv) {                                                       \
    if (const auto status = icd::experiments::benchmark_preamble(argc, argv, program,     \
                                                                 description))            \
      return *status;                                                                     \
    benchmark::Initialize(&argc, argv);                                                   \
    if (const auto status = icd::experiments::benchmark_leftover(argc, argv, program))    \
      return *status;                                                                     \
    benchmark::RunSpecifiedBenchmarks();                                                  \
    benchmark::Shutdown();                                                                \
    return 0;                                                                             \
  }                                                                                       \
  static_assert(true, "")
