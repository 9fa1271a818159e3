// bundle_report FOLDER...
//
// The explicit-FEM quality and fidelity figures of icd-preprocess's summary,
// computed again from the VTU files of an output folder (coarse_tets.vtu and
// dense_surface.vtu) by the same functions (tet_quality, stable_step_report,
// approximate_hausdorff_distance), so that bundles written by any version of
// the pipeline are compared with one evaluator (the preprocess README's
// before/after table of the bunny and the dragon). One tab-separated row per
// folder under a header: tets, vertices, interior nodes and their share,
// dihedral range, largest radius-edge ratio, stable-step ratio against
// near-regular tets (and with the scenes' default mass scaling: ratio and
// added mass), volume of the tets against the dense surface's, and the
// approximate dense-to-coarse Hausdorff distance in % of the dense surface's
// bounding-box diagonal. A folder missing a file or holding a bad one gives
// exit 1 naming the file.
#include <cstdio>
#include <filesystem>
#include <vector>

#include "experiments/common/cli.hpp"
#include "experiments/common/guarded_main.hpp"
#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/mesh_stats.hpp>
#include <icd/mesh/io/vtu_reader.hpp>
#include <icd/mesh/pipeline/fem_step.hpp>
#include <icd/mesh/pipeline/hausdorff.hpp>
#include <icd/mesh/pipeline/tet_quality.hpp>

namespace {

int run(int argc, char** argv) {
  std::vector<std::filesystem::path> folders;
  icd::experiments::Cli cli(
      "bundle_report",
      "  Prints the explicit-FEM quality and fidelity figures of icd-preprocess output\n"
      "  folders (coarse_tets.vtu, dense_surface.vtu), one tab-separated row each.");
  cli.arguments("FOLDER", folders, "icd-preprocess output folders (-o FOLDER)", true);
  if (const auto status = cli.parse(argc, argv)) return *status;

  std::printf(
      "folder\ttets\tvertices\tinterior_nodes\tinterior_share\tmin_dihedral\tmax_dihedral\t"
      "max_radius_edge\tstep_ratio\tscaled_ratio\tadded_mass_pct\tvolume_change_pct\t"
      "hausdorff_pct_diag\n");
  for (const std::filesystem::path& folder : folders) {
    const icd::TetMesh coarse = icd::read_vtu_tet_mesh(folder / "coarse_tets.vtu");
    const icd::SurfaceMesh dense = icd::read_vtu_surface_mesh(folder / "dense_surface.vtu");
    const icd::mesh::TetQuality q = icd::mesh::tet_quality(coarse);
    const icd::mesh::StableStepReport step = icd::mesh::stable_step_report(coarse);
    if (!step.error.empty())
      throw icd::InputError((folder / "coarse_tets.vtu").string() + ": " + step.error);
    const icd::SurfaceStats ds = icd::compute_surface_stats(dense);
    const double diagonal = (ds.bbox_max - ds.bbox_min).norm();
    const double hausdorff =
        icd::mesh::approximate_hausdorff_distance(dense, icd::SurfaceMesh{coarse.V, coarse.F});
    const int interior = q.num_vertices - q.num_surface_nodes;
    std::printf("%s\t%d\t%d\t%d\t%.1f\t%.2f\t%.1f\t%.2f\t%.3f\t%.3f\t%.2f\t%.2f\t%.2f\n",
                folder.string().c_str(), q.num_tets, q.num_vertices, interior,
                100.0 * interior / q.num_vertices, q.min_dihedral_deg, q.max_dihedral_deg,
                q.max_radius_edge, step.ratio, step.scaled_ratio,
                100.0 * step.scaling.added_fraction, 100.0 * (q.total_volume / ds.volume - 1.0),
                100.0 * hausdorff / diagonal);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return icd::experiments::guarded_main("bundle_report", run, argc, argv);
}
