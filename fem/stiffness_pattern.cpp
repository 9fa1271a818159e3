#include <icd/fem/stiffness_pattern.hpp>

#include <algorithm>
#include <cassert>

namespace icd::fem {

StiffnessPattern::StiffnessPattern(int num_nodes, const Eigen::Ref<const MatX4i>& tets) {
  const int nt = static_cast<int>(tets.rows());
  // Node adjacency (including self), sorted and unique per node.
  std::vector<std::vector<int>> adj(num_nodes);
  for (int e = 0; e < nt; ++e)
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b) adj[tets(e, b)].push_back(tets(e, a));
  for (auto& list : adj) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
  }
  const int n = 3 * num_nodes;
  m_column_length.resize(num_nodes);
  std::vector<int> col_start(num_nodes);
  long nnz = 0;
  for (int j = 0; j < num_nodes; ++j) {
    m_column_length[j] = 3 * static_cast<int>(adj[j].size());
    col_start[j] = static_cast<int>(nnz);
    nnz += 3L * m_column_length[j];
  }
  m_zero.resize(n, n);
  m_zero.resizeNonZeros(nnz);
  int* outer = m_zero.outerIndexPtr();
  int* inner = m_zero.innerIndexPtr();
  for (int j = 0; j < num_nodes; ++j)
    for (int c = 0; c < 3; ++c) {
      const int start = col_start[j] + c * m_column_length[j];
      outer[3 * j + c] = start;
      int k = start;
      for (int i : adj[j])
        for (int r = 0; r < 3; ++r) inner[k++] = 3 * i + r;
    }
  outer[n] = static_cast<int>(nnz);
  std::fill_n(m_zero.valuePtr(), nnz, 0.0);
  assert(m_zero.isCompressed());

  m_block_offset.resize(16 * static_cast<size_t>(nt));
  for (int e = 0; e < nt; ++e)
    for (int b = 0; b < 4; ++b) {
      const auto& list = adj[tets(e, b)];
      for (int a = 0; a < 4; ++a) {
        const auto it = std::lower_bound(list.begin(), list.end(), tets(e, a));
        assert(it != list.end() && *it == tets(e, a));
        m_block_offset[16 * e + 4 * b + a] =
            col_start[tets(e, b)] + 3 * static_cast<int>(it - list.begin());
      }
    }
}

void apply_dirichlet(Eigen::SparseMatrix<double>& A, const std::vector<char>& fixed) {
  assert(static_cast<long>(fixed.size()) == A.rows() && A.rows() == A.cols());
  for (int j = 0; j < A.outerSize(); ++j)
    for (Eigen::SparseMatrix<double>::InnerIterator it(A, j); it; ++it)
      if (fixed[it.row()] || fixed[j]) it.valueRef() = (it.row() == j) ? 1.0 : 0.0;
}

}  // namespace icd::fem
