#include "experiments/runner/object_asset.hpp"

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include <icd/coupling/primitive_asset.hpp>
#include <icd/mesh/core/error.hpp>

namespace icd::runner {

void place_object(ObjectAsset& asset, const ObjectSpec& spec) {
  coupling::place_asset(asset, {spec.size, spec.position, spec.rotation_deg});
}

// Bumped whenever icd-preprocess produces different bundles for the same
// input and options (e.g. a better sphere-tree builder), so that cached
// bundles of an older pipeline are not reused.
constexpr const char* kPreprocessVersion = " pipeline-6";

ObjectAsset load_object_asset(const ObjectSpec& spec, const std::filesystem::path& cache_dir,
                              const std::filesystem::path& tool_dir) {
  const PreprocessSpec& pre = spec.preprocess;
  if (spec.primitive) return coupling::make_primitive_asset(*spec.primitive, pre.tree_depth);
  if (!spec.asset.empty()) return coupling::read_asset_bundle(spec.asset);

  // A raw mesh: preprocess it into the cache on first use. The cache folder is
  // named by a hash of the file's bytes, the options and the pipeline version,
  // so any change to these makes a new bundle.
  std::ifstream in(spec.mesh, std::ios::binary);
  if (!in) throw InputError("object \"" + spec.name + "\": cannot open mesh " + spec.mesh.string());
  std::ostringstream bytes;
  bytes << in.rdbuf();
  const bool octree = pre.tree_builder == "octree";
  std::ostringstream args;
  args << " --coarse-tets " << pre.coarse_tets << " --sphere-depth " << pre.tree_depth
       << " --sphere-branching " << pre.tree_branching << (octree ? " --no-spheres" : "");
  // (only when not the default, so that the cached light bundles stay valid)
  if (!octree && pre.tree_fit != "light") args << " --sphere-fit " << pre.tree_fit;
  const std::string key = bytes.str() + args.str() + kPreprocessVersion;
  char hash[17];
  std::snprintf(hash, sizeof hash, "%016llx",
                static_cast<unsigned long long>(coupling::fnv1a64(key.data(), key.size())));
  const std::filesystem::path folder = cache_dir / (spec.mesh.stem().string() + "-" + hash);
  if (!std::filesystem::exists(folder / coupling::kBundleDataFile)) {
    const std::filesystem::path tool = tool_dir / "icd-preprocess";
    if (!std::filesystem::exists(tool))
      throw InputError("object \"" + spec.name + "\": " + spec.mesh.string() +
                       " needs preprocessing but " + tool.string() +
                       " is missing (build the icd-preprocess target)");
    const std::filesystem::path tmp = folder.string() + ".part";
    std::filesystem::remove_all(tmp);
    std::filesystem::create_directories(cache_dir);
    std::fprintf(stderr, "[icd] preprocessing %s (first use, cached in %s)\n", spec.mesh.c_str(),
                 folder.c_str());
    std::ostringstream command;  // (a stream: GCC 12 warns falsely on long string sums)
    command << '"' << tool.string() << "\" \"" << spec.mesh.string() << "\" -o \"" << tmp.string()
            << "\" -q" << args.str();
    const std::string cmd = command.str();
    if (std::system(cmd.c_str()) != 0) {
      std::filesystem::remove_all(tmp);
      throw InputError("object \"" + spec.name + "\": preprocessing " + spec.mesh.string() +
                       " failed (command: " + cmd + ")");
    }
    std::filesystem::remove_all(folder);
    std::filesystem::rename(tmp, folder);
  }
  ObjectAsset a = coupling::read_asset_bundle(folder);
  if (octree) coupling::build_octree_spheres(a, pre.tree_depth);
  return a;
}

}  // namespace icd::runner
