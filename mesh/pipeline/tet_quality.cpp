#include <icd/mesh/pipeline/tet_quality.hpp>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <set>
#include <sstream>

namespace icd::mesh {

TetShape tet_shape(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                   const Eigen::Vector3d& d) {
  const Eigen::Vector3d p[4] = {a, b, c, d};
  TetShape s{};
  // Outward normals of the faces opposite each vertex; the dihedral angle at
  // edge (i, j) is pi minus the angle between the normals of the two faces
  // containing it (those opposite the other two vertices k, l).
  Eigen::Vector3d n[4];
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector3d &u = p[(i + 1) % 4], &v = p[(i + 2) % 4], &w = p[(i + 3) % 4];
    Eigen::Vector3d nn = (v - u).cross(w - u);
    if (nn.dot(p[i] - u) > 0) nn = -nn;  // point away from vertex i
    n[i] = nn.norm() > 0 ? Eigen::Vector3d(nn.normalized()) : Eigen::Vector3d::Zero();
  }
  static constexpr int edges[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
  for (int e = 0; e < 6; ++e) {
    int k = -1, l = -1;
    for (int v = 0; v < 4; ++v)
      if (v != edges[e][0] && v != edges[e][1]) (k < 0 ? k : l) = v;
    const double cosang = std::clamp(-n[k].dot(n[l]), -1.0, 1.0);
    s.dihedral_deg[e] = std::acos(cosang) * 180.0 / std::numbers::pi;
  }
  Eigen::Matrix3d D;
  D << (b - a).transpose(), (c - a).transpose(), (d - a).transpose();
  s.volume = D.determinant() / 6.0;
  double min_edge = std::numeric_limits<double>::infinity();
  for (const auto& e : edges) min_edge = std::min(min_edge, (p[e[0]] - p[e[1]]).norm());
  // Circumcentre x - a solves 2 D (x - a) = |rows|^2.
  const Eigen::Vector3d rhs((b - a).squaredNorm(), (c - a).squaredNorm(), (d - a).squaredNorm());
  const Eigen::FullPivLU<Eigen::Matrix3d> lu(2.0 * D);
  if (s.volume == 0.0 || !lu.isInvertible()) {
    s.radius_edge = std::numeric_limits<double>::infinity();
  } else {
    s.radius_edge = lu.solve(rhs).norm() / min_edge;
  }
  return s;
}

TetQuality tet_quality(const TetMesh& mesh) {
  TetQuality q;
  q.num_vertices = static_cast<int>(mesh.V.rows());
  q.num_tets = static_cast<int>(mesh.T.rows());
  q.num_boundary_faces = static_cast<int>(mesh.F.rows());
  q.num_surface_nodes =
      static_cast<int>(std::set<int>(mesh.F.data(), mesh.F.data() + mesh.F.size()).size());
  q.min_dihedral_deg = 180.0;
  q.min_volume = std::numeric_limits<double>::infinity();
  for (int t = 0; t < q.num_tets; ++t) {
    const TetShape s =
        tet_shape(mesh.V.row(mesh.T(t, 0)).transpose(), mesh.V.row(mesh.T(t, 1)).transpose(),
                  mesh.V.row(mesh.T(t, 2)).transpose(), mesh.V.row(mesh.T(t, 3)).transpose());
    for (double ang : s.dihedral_deg) {
      q.min_dihedral_deg = std::min(q.min_dihedral_deg, ang);
      q.max_dihedral_deg = std::max(q.max_dihedral_deg, ang);
    }
    q.max_radius_edge = std::max(q.max_radius_edge, s.radius_edge);
    q.min_volume = std::min(q.min_volume, s.volume);
    q.total_volume += s.volume;
  }
  if (q.num_tets == 0) q.min_volume = q.min_dihedral_deg = 0.0;
  return q;
}

std::string TetQuality::to_string() const {
  std::ostringstream s;
  s << num_vertices << " vertices (" << num_surface_nodes << " on the surface), " << num_tets
    << " tets, " << num_boundary_faces << " boundary faces\n"
    << "dihedral angles [" << min_dihedral_deg << ", " << max_dihedral_deg
    << "] deg, max radius-edge ratio " << max_radius_edge << ", min volume " << min_volume
    << ", total volume " << total_volume << "\n";
  return s.str();
}

}  // namespace icd::mesh
