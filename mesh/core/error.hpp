#pragma once
/// Errors for user-facing failures: bad files, bad parameters, failed checks.
#include <stdexcept>
#include <string>

namespace icd {

/// A user-facing failure on input: the message names the file (or field) and
/// what is wrong with it, e.g. "bunny.off: line 12: vertex 7 has a NaN coordinate".
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// An impossible or unsupported parameter (negative budget, Poisson ratio >= 0.5...).
/// The message names the parameter and the accepted range.
class ParameterError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// A numerical failure detected by a health check (NaN, inverted element,
/// energy blow-up) after the recovery strategies were exhausted.
class NumericalError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace icd
