#include "experiments/runner/locations.hpp"

#include <cstdlib>
#include <system_error>
#include <vector>

#include <icd/config.hpp>

namespace icd::runner {
namespace fs = std::filesystem;

namespace {

// The value of environment variable `name`, or "" when unset or empty.
std::string env(const char* name) {
  const char* v = std::getenv(name);
  return v != nullptr ? std::string(v) : std::string();
}

bool present(const fs::path& p) {
  std::error_code ec;
  return fs::exists(p, ec);
}

}  // namespace

fs::path program_dir() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  return ec ? fs::current_path() : exe.parent_path();
}

#ifndef ICD_SCENES_FROM_BIN
#define ICD_SCENES_FROM_BIN "../share/icd/scenes"
#endif

bool installed() { return present(program_dir() / ICD_SCENES_FROM_BIN); }

fs::path scenes_dir() {
  if (installed()) return (program_dir() / ICD_SCENES_FROM_BIN).lexically_normal();
  return fs::path(ICD_SOURCE_DIR) / "experiments" / "scenes";
}

fs::path default_cache_dir() {
  if (const std::string d = env("ICD_CACHE_DIR"); !d.empty()) return d;
  if (!installed()) return fs::path(ICD_SOURCE_DIR) / "assets";
  if (const std::string d = env("XDG_CACHE_HOME"); !d.empty() && fs::path(d).is_absolute())
    return fs::path(d) / "icd";
  if (const std::string home = env("HOME"); !home.empty()) return fs::path(home) / ".cache" / "icd";
  return fs::current_path() / ".icd-cache";
}

fs::path resolve_input(const fs::path& p, const fs::path& scene_dir) {
  if (p.empty() || p.is_absolute()) return p;
  std::vector<fs::path> candidates = {scene_dir / p};
  std::error_code ec;
  if (const fs::path cwd = fs::current_path(ec); !ec) candidates.push_back(cwd / p);
  if (const std::string d = env("ICD_DATA_DIR"); !d.empty()) {
    candidates.push_back(fs::path(d) / p);
    candidates.push_back(fs::path(d) / p.filename());
  }
  if (!installed()) candidates.push_back(fs::path(ICD_SOURCE_DIR) / p);
  for (const fs::path& c : candidates)
    if (present(c)) return c;
  return scene_dir / p;
}

}  // namespace icd::runner
