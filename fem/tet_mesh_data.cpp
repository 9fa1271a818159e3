#include <icd/fem/tet_mesh_data.hpp>

#include <cmath>
#include <sstream>

#include <Eigen/LU>

#include <icd/mesh/core/error.hpp>

namespace icd::fem {

Eigen::Matrix<double, 4, 3> TetMeshData::shape_gradients(int e) const {
  Eigen::Matrix<double, 4, 3> g;
  g.bottomRows<3>() = dm_inv[e];
  g.row(0) = -dm_inv[e].colwise().sum();
  return g;
}

Eigen::Matrix3d TetMeshData::deformation_gradient(const Eigen::Ref<const MatX3d>& x, int e) const {
  Eigen::Matrix3d Ds;
  for (int c = 0; c < 3; ++c) Ds.col(c) = (x.row(tets(e, c + 1)) - x.row(tets(e, 0))).transpose();
  return Ds * dm_inv[e];
}

TetMeshData make_tet_mesh_data(const Eigen::Ref<const MatX3d>& rest_positions,
                               const Eigen::Ref<const MatX4i>& tets) {
  const int nv = static_cast<int>(rest_positions.rows());
  const int nt = static_cast<int>(tets.rows());
  if (nv == 0 || nt == 0)
    throw InputError("fem::make_tet_mesh_data: empty mesh (#V = " + std::to_string(nv) +
                     ", #T = " + std::to_string(nt) + ")");
  for (int i = 0; i < nv; ++i)
    if (!rest_positions.row(i).allFinite())
      throw InputError("fem::make_tet_mesh_data: rest position of node " + std::to_string(i) +
                       " is not finite");
  const double diag =
      (rest_positions.colwise().maxCoeff() - rest_positions.colwise().minCoeff()).norm();
  const double min_volume = 1e-14 * diag * diag * diag;

  TetMeshData d;
  d.num_nodes = nv;
  d.rest_positions = rest_positions;
  d.tets = tets;
  d.dm_inv.resize(nt);
  d.rest_volume.resize(nt);
  for (int e = 0; e < nt; ++e) {
    for (int a = 0; a < 4; ++a)
      if (tets(e, a) < 0 || tets(e, a) >= nv) {
        std::ostringstream os;
        os << "fem::make_tet_mesh_data: tet " << e << " vertex " << a << " = " << tets(e, a)
           << " is out of range [0, " << nv << ")";
        throw InputError(os.str());
      }
    Eigen::Matrix3d Dm;
    for (int c = 0; c < 3; ++c)
      Dm.col(c) = (rest_positions.row(tets(e, c + 1)) - rest_positions.row(tets(e, 0))).transpose();
    const double vol = Dm.determinant() / 6.0;
    if (!(vol > min_volume)) {
      std::ostringstream os;
      os << "fem::make_tet_mesh_data: tet " << e << " has rest volume " << vol
         << (vol < 0 ? " (inverted: expected positive orientation)" : " (degenerate)")
         << ", minimum accepted " << min_volume;
      throw InputError(os.str());
    }
    d.dm_inv[e] = Dm.inverse();
    d.rest_volume[e] = vol;
  }
  return d;
}

}  // namespace icd::fem
