#pragma once
/// Quality measures of a tetrahedral mesh (the summary of issue 4, stage 3).
/// Plain Eigen: no CGAL.
#include <string>

#include <icd/mesh/core/types.hpp>

namespace icd::mesh {

/// Quality of a tetrahedral mesh. Angles in degrees, volumes in model units^3.
struct TetQuality {
  int num_vertices = 0, num_tets = 0, num_boundary_faces = 0, num_surface_nodes = 0;
  double min_dihedral_deg = 0.0;  ///< smallest interior dihedral angle over all tets
  double max_dihedral_deg = 0.0;  ///< largest interior dihedral angle over all tets
  /// Largest circumradius / shortest edge (sqrt(6)/4 ~ 0.612 for a regular tet).
  double max_radius_edge = 0.0;
  double min_volume = 0.0;    ///< smallest signed tet volume
  double total_volume = 0.0;  ///< sum of signed tet volumes

  /// A few lines for the tool's summary.
  std::string to_string() const;
};

/// Dihedral angles (6, degrees, at edges 01 02 03 12 13 23), circumradius /
/// shortest edge ratio and signed volume of one tet with vertices a, b, c, d.
/// A degenerate tet gives ratio +infinity and angles of 0 or 180.
struct TetShape {
  double dihedral_deg[6];
  double radius_edge;
  double volume;
};
TetShape tet_shape(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                   const Eigen::Vector3d& d);

/// Quality over all tets of `mesh` (V #V x 3, T #T x 4, F its boundary).
TetQuality tet_quality(const TetMesh& mesh);

}  // namespace icd::mesh
