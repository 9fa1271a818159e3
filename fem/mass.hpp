#pragma once
/// Mass of linear tetrahedra: lumped (diagonal, used by the explicit
/// integrators) and consistent (reference use).
#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <icd/fem/tet_mesh_data.hpp>

namespace icd::fem {

/// Lumped nodal masses (#V), kg: each element gives rho * V_e / 4 to each of
/// its four nodes (row-sum lumping of the consistent mass). Throws
/// icd::ParameterError when density <= 0.
Eigen::VectorXd lumped_mass(const TetMeshData& mesh, double density);

/// Consistent mass matrix (3#V x 3#V, dof 3i+c for node i, axis c), kg:
/// M_ab = rho V_e (1 + delta_ab) / 20 times the 3x3 identity for each element.
/// Its row sums equal lumped_mass(). Throws icd::ParameterError when density <= 0.
Eigen::SparseMatrix<double> consistent_mass_matrix(const TetMeshData& mesh, double density);

}  // namespace icd::fem
