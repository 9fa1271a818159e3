#pragma once
/// Disjoint sets of the integers 0..n-1 (union-find), for grouping mesh
/// elements that share something: a surface's connected components
/// (mesh_stats.cpp), contact pairs that share a node (coupling).
#include <cstdint>
#include <numeric>
#include <utility>
#include <vector>

namespace icd {

/// Union-find with path halving. The root of a merged set is its smallest
/// element, so which element represents a set does not depend on the order
/// of the unions. Indices are not checked (callers pass 0 <= x < size()).
class UnionFind {
 public:
  /// n singletons {0}, {1}, ..., {n-1}.
  explicit UnionFind(int32_t n = 0) { reset(n); }

  /// Back to n singletons (reuses the storage).
  void reset(int32_t n) {
    m_parent.resize(static_cast<size_t>(n));
    std::iota(m_parent.begin(), m_parent.end(), int32_t{0});
  }

  int32_t size() const { return static_cast<int32_t>(m_parent.size()); }

  /// The root (smallest element) of x's set.
  int32_t find(int32_t x) {
    while (m_parent[x] != x) x = m_parent[x] = m_parent[m_parent[x]];
    return x;
  }

  /// Merges the sets of x and y; false when they were one set already.
  bool unite(int32_t x, int32_t y) {
    x = find(x);
    y = find(y);
    if (x == y) return false;
    if (y < x) std::swap(x, y);
    m_parent[y] = x;
    return true;
  }

 private:
  std::vector<int32_t> m_parent;
};

}  // namespace icd
