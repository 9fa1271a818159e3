#include "experiments/studies/spheretree/tree_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include <icd/mesh/core/error.hpp>
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

namespace {

/// The mesh scaled to normalized units (longest side 2000) about its
/// bounding-box centre, which goes to the origin when `centre_origin`.
SurfaceMesh normalized_mesh(const SurfaceMesh& mesh, bool centre_origin) {
  SurfaceMesh scaled = mesh;
  if (centre_origin) scaled.V.rowwise() -= bounding_box_centre(mesh).transpose();
  scaled.V *= to_normalized_units(mesh);
  return scaled;
}

/// The leaf level (the last) in normalized units, about the same origin.
std::vector<collision::Sphere> normalized_leaves(const SurfaceMesh& mesh,
                                                 const collision::SphereTree& tree,
                                                 bool centre_origin) {
  const double scale = to_normalized_units(mesh);
  const Eigen::Vector3d centre =
      centre_origin ? bounding_box_centre(mesh) : Eigen::Vector3d::Zero();
  const int begin = tree.level_offset[static_cast<size_t>(tree.num_levels() - 1)];
  std::vector<collision::Sphere> leaves;
  for (int i = begin; i < tree.num_nodes(); ++i) {
    collision::Sphere s = tree.spheres[static_cast<size_t>(i)];
    s.x = (s.x - centre.x()) * scale, s.y = (s.y - centre.y()) * scale;
    s.z = (s.z - centre.z()) * scale, s.r *= scale;
    leaves.push_back(s);
  }
  return leaves;
}

}  // namespace

GrownLeaves grow_leaves_to_cover(const SurfaceMesh& mesh, const collision::SphereTree& tree,
                                 double spacing) {
  // The evaluator's frame: scaled, not moved (the same doubles as its samples).
  const double scale = to_normalized_units(mesh);
  const SurfaceMesh scaled = normalized_mesh(mesh, false);
  const std::vector<collision::Sphere> leaves = normalized_leaves(mesh, tree, false);
  std::vector<double> reach2(leaves.size());  // squared radius each leaf needs
  for (size_t j = 0; j < leaves.size(); ++j) reach2[j] = leaves[j].r * leaves[j].r;
  GrownLeaves out;
  size_t last = 0;  // the leaf that covered the previous sample (tried first)
  mesh::visit_coverage_samples(
      scaled, spacing, [&](const Eigen::Vector3d& p, const Eigen::Vector3d&, double) {
        auto covers = [&](size_t j) {
          return (p - leaves[j].center()).squaredNorm() <= leaves[j].r * leaves[j].r;
        };
        if (!leaves.empty() && covers(last)) return;
        for (size_t j = 0; j < leaves.size(); ++j) {
          if (covers(j)) {
            last = j;
            return;
          }
        }
        ++out.uncovered_samples;
        size_t best = 0;
        double best_gap = std::numeric_limits<double>::infinity();
        for (size_t j = 0; j < leaves.size(); ++j) {
          const double gap = (p - leaves[j].center()).norm() - leaves[j].r;
          if (gap < best_gap) best_gap = gap, best = j;
        }
        reach2[best] = std::max(reach2[best], (p - leaves[best].center()).squaredNorm());
      });
  out.tree = tree;
  const int begin = tree.level_offset[static_cast<size_t>(tree.num_levels() - 1)];
  for (size_t j = 0; j < leaves.size(); ++j) {
    const double r = std::sqrt(reach2[j]);
    if (r <= leaves[j].r) continue;
    ++out.grown;
    out.largest_growth = std::max(out.largest_growth, r - leaves[j].r);
    out.tree.spheres[static_cast<size_t>(begin) + j].r = r * (1 + 1e-9) / scale;
  }
  out.tree.rest_spheres = out.tree.spheres;
  return out;
}

ShrunkLeaves shrink_leaves_to_coverage_of(const SurfaceMesh& mesh,
                                          const collision::SphereTree& tree,
                                          const collision::SphereTree& other, double spacing) {
  const double scale = to_normalized_units(mesh);
  const std::vector<collision::Sphere> leaves = normalized_leaves(mesh, tree, false),
                                       others = normalized_leaves(mesh, other, false);
  std::vector<double> reach2(leaves.size(), 0.0);
  ShrunkLeaves out;
  size_t last = 0;
  auto inside = [](const collision::Sphere& s, const Eigen::Vector3d& p) {
    return (p - s.center()).squaredNorm() <= s.r * s.r;
  };
  mesh::visit_coverage_samples(
      normalized_mesh(mesh, false), spacing,
      [&](const Eigen::Vector3d& p, const Eigen::Vector3d&, double) {
        if (others.empty() || !inside(others[last], p)) {
          const auto it = std::find_if(others.begin(), others.end(),
                                       [&](const collision::Sphere& s) { return inside(s, p); });
          if (it == others.end()) {
            ++out.dropped_samples;
            return;
          }
          last = static_cast<size_t>(it - others.begin());
        }
        size_t best = leaves.size();
        double best_depth = std::numeric_limits<double>::infinity();
        for (size_t j = 0; j < leaves.size(); ++j) {
          const double d = (p - leaves[j].center()).norm() - leaves[j].r;
          if (d <= 0 && d < best_depth) best_depth = d, best = j;
        }
        if (best == leaves.size())
          throw ParameterError("shrink_leaves_to_coverage_of: the tree leaves a sample uncovered");
        reach2[best] = std::max(reach2[best], (p - leaves[best].center()).squaredNorm());
      });
  out.tree = tree;
  const int begin = tree.level_offset[static_cast<size_t>(tree.num_levels() - 1)];
  for (size_t j = 0; j < leaves.size(); ++j) {
    if (reach2[j] == 0) ++out.emptied;
    out.tree.spheres[static_cast<size_t>(begin) + j].r = std::sqrt(reach2[j]) * (1 + 1e-9) / scale;
  }
  out.tree.rest_spheres = out.tree.spheres;
  return out;
}

void write_leaf_table(std::ostream& out, const SurfaceMesh& mesh,
                      const collision::SphereTree& tree) {
  const mesh::MeshOracle oracle(mesh::close_holes(normalized_mesh(mesh, true)));
  const MatX3d dirs162 = mesh::probe_directions(2), dirs2562 = mesh::probe_directions(4);
  out << "leaf,x,y,z,r,depth,sx,sy,sz,e162,e2562\n";
  char line[512];
  int index = 0;
  for (const collision::Sphere& s : normalized_leaves(mesh, tree, true)) {
    const Eigen::Vector3d c = s.center(), q = oracle.closest_point(c);
    std::snprintf(line, sizeof line, "%d,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f\n",
                  index++, c.x(), c.y(), c.z(), s.r, oracle.signed_distance(c), q.x(), q.y(), q.z(),
                  mesh::sphere_protrusion(oracle, c, s.r, dirs162),
                  mesh::sphere_protrusion(oracle, c, s.r, dirs2562));
    out << line;
  }
}

void write_sample_table(std::ostream& out, const SurfaceMesh& mesh,
                        const collision::SphereTree& tree, double spacing) {
  const std::vector<collision::Sphere> leaves = normalized_leaves(mesh, tree, true);
  out << "x,y,z,nx,ny,nz,w,leaves,reach\n";
  char line[512];
  mesh::visit_coverage_samples(
      normalized_mesh(mesh, true), spacing,
      [&](const Eigen::Vector3d& p, const Eigen::Vector3d& n, double weight) {
        int count = 0;
        double reach = 0;
        for (const collision::Sphere& s : leaves) {
          const Eigen::Vector3d d = s.center() - p;
          if (d.squaredNorm() > s.r * s.r) continue;
          ++count;
          const double along = d.dot(n);
          reach = std::max(
              reach, along + std::sqrt(std::max(0.0, s.r * s.r - d.squaredNorm() + along * along)));
        }
        std::snprintf(line, sizeof line, "%.3f,%.3f,%.3f,%.4f,%.4f,%.4f,%.5g,%d,%.3f\n", p.x(),
                      p.y(), p.z(), n.x(), n.y(), n.z(), weight, count, reach);
        out << line;
      });
}

}  // namespace icd::experiments
