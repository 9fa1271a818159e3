#include "experiments/runner/object_asset.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <optional>
#include <vector>

#include <icd/coupling/primitive_asset.hpp>
#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/input_file.hpp>

#include "experiments/runner/child_process.hpp"

namespace icd::runner {

namespace {

/// An exclusive advisory lock (flock) on `path`, held while the object lives:
/// processes preprocessing the same mesh into the same cache (a sweep's
/// parallel cases) take turns instead of writing one folder together.
class CacheLock {
 public:
  explicit CacheLock(const std::filesystem::path& path) {
    m_fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (m_fd < 0)
      throw InputError("cannot open the asset cache lock " + escape_bytes(path.string(), 4096));
    if (::flock(m_fd, LOCK_EX | LOCK_NB) != 0) {
      std::fprintf(stderr, "[icd] waiting for another process preprocessing into %s\n",
                   escape_bytes(path.parent_path().string(), 4096).c_str());
      while (::flock(m_fd, LOCK_EX) != 0) {
        if (errno != EINTR) {
          ::close(m_fd);
          throw InputError("cannot lock the asset cache lock " + escape_bytes(path.string(), 4096));
        }
      }
    }
  }
  ~CacheLock() { ::close(m_fd); }  // closing releases the lock
  CacheLock(const CacheLock&) = delete;
  CacheLock& operator=(const CacheLock&) = delete;

 private:
  int m_fd = -1;
};

}  // namespace

void place_object(ObjectAsset& asset, const ObjectSpec& spec) {
  coupling::place_asset(asset, {spec.size, spec.position, spec.rotation_deg});
}

// Bumped whenever icd-preprocess produces different bundles for the same
// input and options (e.g. a better sphere-tree builder), so that cached
// bundles of an older pipeline are not reused.
constexpr const char* kPreprocessVersion = " pipeline-13";

namespace {

std::string object_label(const ObjectSpec& spec) { return "object \"" + spec.name + "\": "; }

// Runs `f`; an InputError it throws gets the object's name in front.
template <class F>
auto naming_object(const ObjectSpec& spec, F&& f) {
  try {
    return f();
  } catch (const InputError& e) {
    throw InputError(object_label(spec) + e.what());
  } catch (const ParameterError& e) {
    throw ParameterError(object_label(spec) + e.what());
  }
}

bool is_surface_mesh_extension(const std::filesystem::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext == ".off" || ext == ".obj" || ext == ".ply" || ext == ".stl";
}

}  // namespace

void check_object_inputs(const ObjectSpec& spec) {
  naming_object(spec, [&] {
    if (!spec.mesh.empty()) {
      check_input_file(spec.mesh, file_limits::kSurfaceMesh, "mesh");
      if (!is_surface_mesh_extension(spec.mesh))
        throw InputError(
            escape_bytes(spec.mesh.string(), 4096) + ": unknown mesh file extension '" +
            escape_bytes(spec.mesh.extension().string()) + "' (supported: .off, .obj, .ply, .stl)");
    }
    if (!spec.asset.empty()) {
      check_input_file(spec.asset / coupling::kBundleDataFile, file_limits::kBundle,
                       "asset bundle file");
      check_input_file(spec.asset / coupling::kDenseSurfaceFile, file_limits::kVtu, "VTU file");
      check_input_file(spec.asset / coupling::kCoarseTetsFile, file_limits::kVtu, "VTU file");
    }
    return 0;
  });
}

ObjectAsset load_object_asset(const ObjectSpec& spec, const std::filesystem::path& cache_dir,
                              const std::filesystem::path& tool_dir, const ChildLimits& limits) {
  const PreprocessSpec& pre = spec.preprocess;
  if (spec.primitive)
    return naming_object(
        spec, [&] { return coupling::make_primitive_asset(*spec.primitive, pre.tree_depth); });
  if (!spec.asset.empty())
    return naming_object(spec, [&] { return coupling::read_asset_bundle(spec.asset); });

  // A raw mesh: preprocess it into the cache on first use. The cache folder is
  // named by a hash of the file's bytes, the options and the pipeline version,
  // so any change to these makes a new bundle.
  check_object_inputs(spec);
  const std::string bytes = naming_object(
      spec, [&] { return read_input_file(spec.mesh, file_limits::kSurfaceMesh, "mesh"); });
  const bool octree = pre.tree_builder == "octree";
  std::vector<std::string> options = {"--coarse-tets",      std::to_string(pre.coarse_tets),
                                      "--sphere-depth",     std::to_string(pre.tree_depth),
                                      "--sphere-branching", std::to_string(pre.tree_branching)};
  if (octree) options.push_back("--no-spheres");
  // (only when not the default, so that the cached light bundles stay valid)
  if (!octree && pre.tree_fit != "light") {
    options.push_back("--sphere-fit");
    options.push_back(pre.tree_fit);
  }
  std::string args;  // the options as they entered the cache key before (" --coarse-tets 1500 ...")
  for (const std::string& o : options) args += " " + o;
  const std::string key = bytes + args + kPreprocessVersion;
  char hash[17];
  std::snprintf(hash, sizeof hash, "%016llx",
                static_cast<unsigned long long>(coupling::fnv1a64(key.data(), key.size())));
  const std::filesystem::path folder = cache_dir / (spec.mesh.stem().string() + "-" + hash);
  std::optional<CacheLock> lock;
  if (!std::filesystem::exists(folder / coupling::kBundleDataFile)) {
    std::filesystem::create_directories(cache_dir);
    lock.emplace(folder.string() + ".lock");
  }
  // Checked again under the lock: another process may have just written it.
  if (!std::filesystem::exists(folder / coupling::kBundleDataFile)) {
    const std::filesystem::path tool = tool_dir / "icd-preprocess";
    if (!std::filesystem::exists(tool))
      throw InputError(object_label(spec) + escape_bytes(spec.mesh.string(), 4096) +
                       " needs preprocessing but " + escape_bytes(tool.string(), 4096) +
                       " is missing (build the icd-preprocess target)");
    const std::filesystem::path tmp = folder.string() + ".part";
    std::filesystem::remove_all(tmp);
    std::filesystem::create_directories(cache_dir);
    std::fprintf(stderr, "[icd] preprocessing %s (first use, cached in %s)\n",
                 escape_bytes(spec.mesh.string(), 4096).c_str(),
                 escape_bytes(folder.string(), 4096).c_str());
    // No shell: the paths are arguments, never interpreted. Absolute, so that
    // a path starting with '-' is not taken for an option.
    std::vector<std::string> argv = {tool.string(), std::filesystem::absolute(spec.mesh).string(),
                                     "-o", std::filesystem::absolute(tmp).string(), "-q"};
    argv.insert(argv.end(), options.begin(), options.end());
    const ChildResult result = run_child(argv, limits);
    if (!result.ok()) {
      std::filesystem::remove_all(tmp);
      throw InputError(object_label(spec) + "preprocessing " +
                       escape_bytes(spec.mesh.string(), 4096) + " failed: icd-preprocess " +
                       result.describe(limits) + " (command: " + display_command(argv) + ")");
    }
    std::filesystem::remove_all(folder);
    std::filesystem::rename(tmp, folder);
  }
  ObjectAsset a = coupling::read_asset_bundle(folder);
  if (octree) coupling::build_octree_spheres(a, pre.tree_depth);
  return a;
}

}  // namespace icd::runner
