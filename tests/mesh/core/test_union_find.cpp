// UnionFind against breadth-first search over the same edges (an
// independent computation of the connected components), on random graphs
// from sparse to dense, and the documented details: the root is the
// smallest element, unite() says whether it merged, reset() starts over.
#include <gtest/gtest.h>

#include <deque>
#include <random>
#include <utility>
#include <vector>

#include <icd/mesh/core/union_find.hpp>

namespace icd {
namespace {

// Component label per vertex: the smallest vertex of its component (BFS).
std::vector<int32_t> bfs_components(int32_t n, const std::vector<std::pair<int32_t, int32_t>>& edges) {
  std::vector<std::vector<int32_t>> adjacent(static_cast<size_t>(n));
  for (const auto& [x, y] : edges) {
    adjacent[x].push_back(y);
    adjacent[y].push_back(x);
  }
  std::vector<int32_t> label(static_cast<size_t>(n), -1);
  for (int32_t s = 0; s < n; ++s) {  // in increasing order: s is its component's smallest
    if (label[s] >= 0) continue;
    std::deque<int32_t> queue{s};
    label[s] = s;
    while (!queue.empty()) {
      const int32_t x = queue.front();
      queue.pop_front();
      for (int32_t y : adjacent[x])
        if (label[y] < 0) {
          label[y] = s;
          queue.push_back(y);
        }
    }
  }
  return label;
}

TEST(UnionFind, MatchesBreadthFirstSearchOnRandomGraphs) {
  std::mt19937 rng(0);
  for (int32_t n : {1, 2, 7, 100, 2000})
    for (double edges_per_vertex : {0.0, 0.3, 0.6, 1.0, 3.0}) {
      std::uniform_int_distribution<int32_t> vertex(0, n - 1);
      std::vector<std::pair<int32_t, int32_t>> edges;
      for (int e = 0; e < static_cast<int>(edges_per_vertex * n); ++e)
        edges.emplace_back(vertex(rng), vertex(rng));
      const std::vector<int32_t> label = bfs_components(n, edges);
      UnionFind sets(n);
      int merges = 0;
      for (const auto& [x, y] : edges) merges += sets.unite(x, y) ? 1 : 0;
      int components = 0;
      for (int32_t x = 0; x < n; ++x) {
        components += label[x] == x;
        ASSERT_EQ(sets.find(x), label[x]) << "n " << n << ", vertex " << x;
      }
      // Each merge joins two sets: n singletons end as `components` sets.
      EXPECT_EQ(merges, n - components) << "n " << n << ", " << edges.size() << " edges";
    }
}

TEST(UnionFind, RootIsTheSmallestElementWhateverTheOrder) {
  UnionFind sets(6);
  EXPECT_TRUE(sets.unite(5, 4));
  EXPECT_TRUE(sets.unite(4, 3));
  EXPECT_FALSE(sets.unite(3, 5));  // one set already
  EXPECT_TRUE(sets.unite(1, 5));
  for (int32_t x : {1, 3, 4, 5}) EXPECT_EQ(sets.find(x), 1);
  EXPECT_EQ(sets.find(0), 0);
  EXPECT_EQ(sets.find(2), 2);
  EXPECT_FALSE(sets.unite(2, 2));
}

TEST(UnionFind, ResetStartsOverWithSingletons) {
  UnionFind sets(4);
  sets.unite(0, 3);
  sets.unite(1, 2);
  sets.reset(5);
  EXPECT_EQ(sets.size(), 5);
  for (int32_t x = 0; x < 5; ++x) EXPECT_EQ(sets.find(x), x);
  UnionFind empty;
  EXPECT_EQ(empty.size(), 0);
}

TEST(UnionFind, LongChainStaysCorrect) {
  // A path 0-1-...-n-1 united from the far end: deep trees before halving.
  const int32_t n = 100000;
  UnionFind sets(n);
  for (int32_t x = n - 1; x > 0; --x) EXPECT_TRUE(sets.unite(x, x - 1));
  for (int32_t x = 0; x < n; x += 997) EXPECT_EQ(sets.find(x), 0);
  EXPECT_FALSE(sets.unite(n - 1, 0));
}

}  // namespace
}  // namespace icd
