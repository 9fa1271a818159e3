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
#include <exception>
#include <iostream>

namespace icd::experiments {

/// Returns run(argc, argv), or 1 after printing "<program>: <message>" on
/// stderr when it throws (any exception: "unknown error" for one that is
/// not a std::exception).
template <class Run>
int guarded_main(const char* program, Run&& run, int argc, char** argv) noexcept {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << program << ": " << e.what() << "\n";
  } catch (...) {
    std::cerr << program << ": unknown error\n";
  }
  return 1;
}

}  // namespace icd::experiments
