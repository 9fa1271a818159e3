#include "experiments/studies/spheretree/tree_report.hpp"

#include <algorithm>
#include <cstdio>

#include <icd/mesh/spheres/mesh_oracle.hpp>
#include <icd/mesh/spheres/protrusion.hpp>

namespace icd::experiments {

void print_level_table_header() {
  std::printf(
      "# errors in units where the longest bounding-box side is 2000; error = largest distance\n"
      "# from a probe outside the (hole-closed) mesh to the surface (42 or 162 probes in our\n"
      "# frame; worst42r / mean42r: 42 probes averaged over random orientations, 16 per sphere\n"
      "# unless said otherwise, which no tree can have been fitted to); coverage on a dense\n"
      "# sampling (spacing 1 unit unless said otherwise),\n"
      "# gap = largest distance of an uncovered sample to a sphere; redund = spheres that cover\n"
      "# no vertex or dense sample alone (each removable alone without uncovering anything),\n"
      "# mean42c / mean162c = means over the other spheres; shell = volume of the level's union\n"
      "# outside the object / surface area (the mean thickness of the shell it adds); t50 / t90 =\n"
      "# area-weighted median / 90th percentile over the surface of how far the spheres\n"
      "# containing a point reach from it along the outward normal.\n");
  std::printf(
      "%-7s %-7s %5s %7s %9s %8s %9s %8s %9s %8s %11s %8s %7s %6s %9s %8s %6s %8s %8s %7s %7s "
      "%7s\n",
      "model", "method", "level", "spheres", "worst42", "mean42", "worst42r", "mean42r", "worst162",
      "mean162", "uncovered", "unc.pts", "gap", "unc.v", "protrude", "build_s", "redund", "mean42c",
      "mean162c", "shell", "t50", "t90");
}

void print_level_table(const std::string& model, const std::string& method, double seconds,
                       const std::vector<mesh::LevelMetrics>& levels) {
  for (const auto& m : levels) {
    std::printf(
        "%-7s %-7s %5d %7d %9.1f %8.2f %9.1f %8.2f %9.1f %8.2f %10.5f%% %8lld %7.2f %6d %9.1f "
        "%8.2f %6d %8.2f %8.2f %7.2f %7.2f %7.2f\n",
        model.c_str(), method.c_str(), m.level, m.num_spheres, m.worst_error_42, m.mean_error_42,
        m.worst_error_42_rotated, m.mean_error_42_rotated, m.worst_error_162, m.mean_error_162,
        100.0 * m.uncovered_area_fraction, m.num_uncovered_samples, m.max_uncovered_gap,
        m.num_uncovered_vertices, m.max_child_protrusion, seconds, m.num_redundant_spheres,
        m.mean_error_42_covering, m.mean_error_162_covering, m.shell_thickness, m.thickness_median,
        m.thickness_p90);
  }
}

std::vector<LevelError> dense_errors(const SurfaceMesh& mesh, const collision::SphereTree& tree,
                                     double to_2000) {
  const mesh::MeshOracle oracle(mesh::close_holes(mesh));
  const MatX3d dirs = mesh::probe_directions(4);
  std::vector<LevelError> out;
  for (int l = 0; l < tree.num_levels(); ++l) {
    LevelError e;
    double sum = 0;
    const int begin = tree.level_offset[static_cast<size_t>(l)],
              end = tree.level_offset[static_cast<size_t>(l) + 1];
    for (int i = begin; i < end; ++i) {
      const auto& s = tree.spheres[static_cast<size_t>(i)];
      const double err = to_2000 * mesh::sphere_protrusion(oracle, s.center(), s.r, dirs);
      e.worst = std::max(e.worst, err), sum += err;
    }
    e.mean = end > begin ? sum / (end - begin) : 0.0;
    out.push_back(e);
  }
  return out;
}

void print_dense_errors(const std::string& label, const SurfaceMesh& mesh,
                        const collision::SphereTree& tree, double to_2000) {
  const std::vector<LevelError> errors = dense_errors(mesh, tree, to_2000);
  for (size_t l = 0; l < errors.size(); ++l)
    std::printf("# %s level %zu: error on 2562 directions: worst %.1f mean %.2f\n", label.c_str(),
                l, errors[l].worst, errors[l].mean);
}

double to_normalized_units(const SurfaceMesh& mesh) {
  return 2000.0 / (mesh.V.colwise().maxCoeff() - mesh.V.colwise().minCoeff()).maxCoeff();
}

Eigen::Vector3d bounding_box_centre(const SurfaceMesh& mesh) {
  return 0.5 * (mesh.V.colwise().minCoeff() + mesh.V.colwise().maxCoeff()).transpose();
}

collision::SphereTree read_sph_for_mesh(const std::string& path, const SurfaceMesh& mesh,
                                        bool centred) {
  collision::SphereTree tree = collision::read_sph(path);
  if (centred) {
    const Eigen::Vector3d centre = bounding_box_centre(mesh);
    for (auto& s : tree.spheres) s.x += centre.x(), s.y += centre.y(), s.z += centre.z();
    tree.rest_spheres = tree.spheres;
  }
  return tree;
}

}  // namespace icd::experiments
