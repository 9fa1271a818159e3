#pragma once
/// Precomputed per-element rest data of linear tetrahedra: the inverse rest
/// edge matrix Dm^-1, the rest volume and the shape-function gradients.
#include <vector>

#include <Eigen/Core>

#include <icd/mesh/core/types.hpp>

namespace icd::fem {

/// Rest data of a tet mesh. For element e with rest vertices X0..X3,
/// Dm = [X1-X0, X2-X0, X3-X0] and the deformation gradient of current
/// positions x is F = Ds Dm^-1 with Ds = [x1-x0, x2-x0, x3-x0]
/// (O'Brien & Hodgins; paper section 3).
struct TetMeshData {
  int num_nodes = 0;                    ///< #V
  MatX3d rest_positions;                ///< V (#V x 3), metres
  MatX4i tets;                          ///< T (#T x 4), positively oriented
  std::vector<Eigen::Matrix3d> dm_inv;  ///< Dm^-1 of every element (#T)
  Eigen::VectorXd rest_volume;          ///< rest volume of every element (#T), m^3, > 0

  int num_tets() const { return static_cast<int>(tets.rows()); }

  /// Shape-function gradients of element e: row a is grad N_a (1/m), a = 0..3;
  /// rows 1..3 are the rows of Dm^-1, row 0 is minus their sum.
  Eigen::Matrix<double, 4, 3> shape_gradients(int e) const;

  /// Deformation gradient F = Ds Dm^-1 of element e for positions x (#V x 3).
  Eigen::Matrix3d deformation_gradient(const Eigen::Ref<const MatX3d>& x, int e) const;
};

/// Builds the rest data. Throws icd::InputError naming the element when an
/// index is out of range, a coordinate is not finite, or a tet has volume
/// <= 1e-14 * (bounding-box diagonal)^3 (degenerate or inverted).
TetMeshData make_tet_mesh_data(const Eigen::Ref<const MatX3d>& rest_positions,
                               const Eigen::Ref<const MatX4i>& tets);

}  // namespace icd::fem
