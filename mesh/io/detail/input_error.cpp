#include <icd/mesh/io/detail/input_error.hpp>

#include <icd/mesh/core/error.hpp>

namespace icd::detail {

void throw_input_error(std::string_view source, int64_t line, std::string_view what) {
  std::string msg(source);
  msg += ": ";
  if (line >= 1) msg += "line " + std::to_string(line) + ": ";
  msg += what;
  throw InputError(msg);
}

void throw_input_error(std::string_view source, std::string_view what) {
  throw_input_error(source, 0, what);
}

void check_count_fits(std::string_view source, int64_t line, std::string_view what, int64_t count,
                      int64_t min_bytes_each, int64_t bytes_left, int64_t max_count) {
  if (count < 0)
    throw_input_error(
        source, line,
        "negative number of " + std::string(what) + " (" + std::to_string(count) + ")");
  if (count > max_count)
    throw_input_error(source, line,
                      "header announces " + std::to_string(count) + " " + std::string(what) +
                          ", more than the supported maximum " + std::to_string(max_count));
  if (min_bytes_each > 0 && count > (bytes_left + 1) / min_bytes_each)
    throw_input_error(source, line,
                      "truncated file: header announces " + std::to_string(count) + " " +
                          std::string(what) + " (at least " + std::to_string(min_bytes_each) +
                          " bytes each) but only " + std::to_string(bytes_left) + " bytes follow");
}

}  // namespace icd::detail
