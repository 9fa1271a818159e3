#pragma once
/// The one main() wrapper of the programs whose work is a `run(argc, argv)`
/// that throws on bad input (InputError naming the file or field,
/// ParameterError, std::bad_alloc...): the message goes to stderr as
///   <program>: <what>
/// and the exit status is 1, with nothing more written.
///
///   int main(int argc, char** argv) {
///     return icd::experiments::guarded_main("evaluate_sph", run, argc, argv);
///   }
///
/// A program whose options go to a library that validates them may name the
/// exception type that means "bad option value" (bad usage, status 2, as a
/// command-line error of cli.hpp):
///   return guarded_main<icd::ParameterError>("icd-preprocess", run, argc, argv);
/// prints "<program>: invalid option: <what>" and returns 2 for it.
/// Under a memory limit the process ends without the libraries' shutdown
/// (exit_without_library_shutdown_under_memory_limits: OpenBLAS's would hang).
#include <exception>
#include <iostream>

#include "experiments/common/process_exit.hpp"

namespace icd::experiments {

namespace detail {
/// The default usage-error type of guarded_main: never thrown.
struct NoUsageError {
  const char* what() const noexcept { return ""; }
};
}  // namespace detail

/// Returns run(argc, argv), or, when it throws: 2 after printing
/// "<program>: invalid option: <message>" on stderr for a UsageError, else 1
/// after printing "<program>: <message>" (any exception: "unknown error" for
/// one that is not a std::exception).
template <class UsageError = detail::NoUsageError, class Run>
int guarded_main(const char* program, Run&& run, int argc, char** argv) noexcept {
  exit_without_library_shutdown_under_memory_limits();
  try {
    return run(argc, argv);
  } catch (const UsageError& e) {
    std::cerr << program << ": invalid option: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << program << ": " << e.what() << "\n";
  } catch (...) {
    std::cerr << program << ": unknown error\n";
  }
  return 1;
}

}  // namespace icd::experiments
