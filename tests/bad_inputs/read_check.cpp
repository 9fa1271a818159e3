// icd-read-check PATH: loads a `.sph` sphere tree or an asset bundle folder
// with the library readers (no other program reads these on their own) and
// reports the outcome like the other tools: a summary line and exit 0, or
// "icd-read-check: <error>" on stderr and exit 1. Used by the bad-input test.
#include <cstdio>
#include <filesystem>
#include <string>

#include <icd/collision/sph_io.hpp>
#include <icd/coupling/asset_bundle.hpp>
#include "experiments/common/cli.hpp"
#include "experiments/common/guarded_main.hpp"

namespace {

int run(int argc, char** argv) {
  std::filesystem::path path;
  icd::experiments::Cli cli("icd-read-check",
                            "  Loads a .sph sphere tree or an asset bundle folder and prints a "
                            "summary.");
  cli.argument("PATH", path, "FILE.sph or BUNDLE_FOLDER", true);
  if (const auto status = cli.parse(argc, argv)) return *status;
  if (std::filesystem::is_directory(path)) {
    const icd::coupling::AssetBundle b = icd::coupling::read_asset_bundle(path);
    std::printf("%s: bundle, %ld dense vertices, %ld coarse tets, %d spheres\n", path.c_str(),
                static_cast<long>(b.dense.V.rows()), static_cast<long>(b.coarse.T.rows()),
                b.spheres.num_nodes());
  } else {
    const icd::collision::SphereTree t = icd::collision::read_sph(path.string());
    std::printf("%s: sphere tree, %d nodes, %d levels\n", path.c_str(), t.num_nodes(), t.num_levels());
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return icd::experiments::guarded_main("icd-read-check", run, argc, argv);
}
