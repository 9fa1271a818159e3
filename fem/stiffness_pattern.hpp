#pragma once
/// Precomputed sparsity pattern of a 3#V x 3#V tet-mesh matrix (3x3 block per
/// pair of nodes sharing an element) and, per element, where its 16 blocks
/// live in the value array, so that re-assembly writes values in place.
#include <vector>

#include <Eigen/SparseCore>

#include <icd/mesh/core/types.hpp>

namespace icd::fem {

/// Pattern of a column-major 3#V x 3#V matrix with full (both triangles) 3x3
/// node blocks. Entry (3 T(e,a) + r, 3 T(e,b) + c) of element e is stored at
/// valuePtr()[block_offset[16 e + 4 b + a] + r + c * column_length[T(e,b)]].
class StiffnessPattern {
 public:
  /// Builds the pattern of #V nodes and tets T (#T x 4, indices in [0, #V)).
  StiffnessPattern(int num_nodes, const Eigen::Ref<const MatX4i>& tets);

  /// A matrix with this pattern and all values zero (compressed, sorted).
  const Eigen::SparseMatrix<double>& zero_matrix() const { return m_zero; }

  /// Value index of entry (3 T(e,a), 3 T(e,b)).
  int block_offset(int e, int a, int b) const { return m_block_offset[16 * e + 4 * b + a]; }
  /// Number of stored entries in each column of node j (3 x its neighbour count).
  int column_length(int j) const { return m_column_length[j]; }

 private:
  Eigen::SparseMatrix<double> m_zero;
  std::vector<int> m_block_offset;
  std::vector<int> m_column_length;
};

/// Applies Dirichlet conditions in place without changing the pattern: for
/// every dof d with fixed[d] != 0, zeroes row d and column d and sets A(d,d) = 1.
/// fixed has 3#V entries (dof 3i+c).
void apply_dirichlet(Eigen::SparseMatrix<double>& A, const std::vector<char>& fixed);

}  // namespace icd::fem
