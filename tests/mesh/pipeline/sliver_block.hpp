#pragma once
// A BCC block with one flat sliver, shared by the stable-step and cleanup tests.
#include <icd/mesh/pipeline/fem_step.hpp>
#include <icd/mesh/pipeline/tet_quality.hpp>

namespace icd::mesh::test {

/// bcc_block(4, 1) with its interior lattice node at (1.5, 1.5, 1.5) moved 92 %
/// of the way to the plane of the opposite face of one of its tets, the first
/// tet (in T's order) for which that leaves every tet positive and the
/// smallest dihedral angle under 10 deg. Returns false (mesh unchanged) when
/// no tet does.
inline bool bcc_block_with_centre_sliver(TetMesh& m) {
  m = bcc_block(4, 1.0);
  Eigen::Index c = -1;
  for (Eigen::Index i = 0; i < m.V.rows(); ++i)
    if ((m.V.row(i) - Eigen::RowVector3d(1.5, 1.5, 1.5)).norm() < 1e-12) c = i;
  if (c < 0) return false;
  const Eigen::RowVector3d rest = m.V.row(c);
  for (Eigen::Index t = 0; t < m.T.rows(); ++t) {
    int k = -1;
    for (int a = 0; a < 4; ++a)
      if (m.T(t, a) == c) k = a;
    if (k < 0) continue;
    const Eigen::Vector3d p0 = m.V.row(m.T(t, (k + 1) % 4)), p1 = m.V.row(m.T(t, (k + 2) % 4)),
                          p2 = m.V.row(m.T(t, (k + 3) % 4));
    const Eigen::Vector3d n = (p1 - p0).cross(p2 - p0).normalized();
    const Eigen::Vector3d x = rest.transpose();
    m.V.row(c) = (x - 0.92 * n.dot(x - p0) * n).transpose();
    const TetQuality q = tet_quality(m);
    if (q.min_volume > 0 && q.min_dihedral_deg < 10.0) return true;
    m.V.row(c) = rest;
  }
  return false;
}

}  // namespace icd::mesh::test
