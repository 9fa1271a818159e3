#include <icd/fem/reorder.hpp>

#include <algorithm>
#include <numeric>
#include <string>

#include <icd/mesh/core/error.hpp>

namespace icd::fem {
namespace {

// BFS levels from `start` over unvisited-in-component nodes; returns the order
// and writes the last level's minimum-degree node into `far`.
std::vector<int> bfs(int start, const std::vector<int>& off, const std::vector<int>& adj,
                     const std::vector<int>& degree, std::vector<char>& mark, int& far,
                     int& depth) {
  std::vector<int> order{start};
  mark[start] = 1;
  size_t level_begin = 0;
  depth = 0;
  while (true) {
    const size_t level_end = order.size();
    std::vector<int> next;
    for (size_t k = level_begin; k < level_end; ++k) {
      const int u = order[k];
      std::vector<int> nb;
      for (int j = off[u]; j < off[u + 1]; ++j)
        if (!mark[adj[j]]) {
          mark[adj[j]] = 1;
          nb.push_back(adj[j]);
        }
      std::stable_sort(nb.begin(), nb.end(), [&](int a, int b) { return degree[a] < degree[b]; });
      order.insert(order.end(), nb.begin(), nb.end());
    }
    if (order.size() == level_end) {
      far = *std::min_element(order.begin() + level_begin, order.begin() + level_end,
                              [&](int a, int b) { return degree[a] < degree[b]; });
      break;
    }
    level_begin = level_end;
    ++depth;
  }
  return order;
}

}  // namespace

ReorderedMesh reorder_for_locality(const Eigen::Ref<const MatX3d>& V,
                                   const Eigen::Ref<const MatX4i>& T) {
  const int nv = static_cast<int>(V.rows()), nt = static_cast<int>(T.rows());
  for (int e = 0; e < nt; ++e)
    for (int a = 0; a < 4; ++a)
      if (T(e, a) < 0 || T(e, a) >= nv)
        throw InputError("fem::reorder_for_locality: tet " + std::to_string(e) + " vertex " +
                         std::to_string(a) + " = " + std::to_string(T(e, a)) +
                         " is out of range [0, " + std::to_string(nv) + ")");
  // Node graph (CSR, unique neighbours).
  std::vector<std::vector<int>> lists(nv);
  for (int e = 0; e < nt; ++e)
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b)
        if (a != b) lists[T(e, a)].push_back(T(e, b));
  std::vector<int> off(nv + 1, 0), adj, degree(nv);
  for (int i = 0; i < nv; ++i) {
    auto& l = lists[i];
    std::sort(l.begin(), l.end());
    l.erase(std::unique(l.begin(), l.end()), l.end());
    degree[i] = static_cast<int>(l.size());
    off[i + 1] = off[i] + degree[i];
    adj.insert(adj.end(), l.begin(), l.end());
  }
  std::vector<char> done(nv, 0);
  std::vector<int> order;
  order.reserve(nv);
  for (int seed = 0; seed < nv; ++seed) {
    if (done[seed]) continue;
    // Pseudo-peripheral start: repeat BFS from the far end while the depth grows.
    int start = seed, far = seed, depth = -1;
    for (int pass = 0; pass < 4; ++pass) {
      std::vector<char> mark = done;
      int d = 0, f = start;
      bfs(start, off, adj, degree, mark, f, d);
      if (d <= depth) break;
      depth = d;
      far = start;
      start = f;
    }
    start = far;
    std::vector<char> mark = done;
    int f = 0, d = 0;
    const std::vector<int> comp = bfs(start, off, adj, degree, mark, f, d);
    for (int u : comp) done[u] = 1;
    order.insert(order.end(), comp.begin(), comp.end());
  }
  std::reverse(order.begin(), order.end());

  ReorderedMesh r;
  r.new_to_old_node = order;
  r.old_to_new_node.assign(nv, -1);
  for (int i = 0; i < nv; ++i) r.old_to_new_node[order[i]] = i;
  r.V.resize(nv, 3);
  for (int i = 0; i < nv; ++i) r.V.row(i) = V.row(order[i]);
  std::vector<int> key(nt);
  for (int e = 0; e < nt; ++e) {
    key[e] = nv;
    for (int a = 0; a < 4; ++a) key[e] = std::min(key[e], r.old_to_new_node[T(e, a)]);
  }
  r.new_to_old_element.resize(nt);
  std::iota(r.new_to_old_element.begin(), r.new_to_old_element.end(), 0);
  std::stable_sort(r.new_to_old_element.begin(), r.new_to_old_element.end(),
                   [&](int a, int b) { return key[a] < key[b]; });
  r.T.resize(nt, 4);
  for (int e = 0; e < nt; ++e)
    for (int a = 0; a < 4; ++a) r.T(e, a) = r.old_to_new_node[T(r.new_to_old_element[e], a)];
  return r;
}

int node_bandwidth(const Eigen::Ref<const MatX4i>& T) {
  int bw = 0;
  for (int e = 0; e < T.rows(); ++e) bw = std::max(bw, T.row(e).maxCoeff() - T.row(e).minCoeff());
  return bw;
}

}  // namespace icd::fem
