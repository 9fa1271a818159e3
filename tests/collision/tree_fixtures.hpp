#pragma once
// Shared helpers of the collision tests: trees over small meshes, ancestor
// checks and oracles.
#include <algorithm>
#include <random>
#include <set>
#include <vector>

#include <icd/collision/octree_tree.hpp>
#include <icd/collision/traversal.hpp>
#include <icd/mesh/core/primitives.hpp>

namespace icd::collision::testing {

inline SurfaceMesh translated(SurfaceMesh m, const Eigen::Vector3d& t) {
  m.V.rowwise() += t.transpose();
  return m;
}

inline bool is_ancestor_or_self(const std::vector<int32_t>& parent, int anc, int node) {
  for (int n = node; n >= 0; n = parent[n])
    if (n == anc) return true;
  return false;
}

// Enlarges parents bottom-up so that every child sphere lies inside its
// parent (a layered tree): then a full traversal must find exactly the
// overlapping leaf pairs.
inline SphereTree layered(SphereTree t) {
  for (int i = t.num_nodes() - 1; i >= 0; --i)
    for (int c = 0; c < t.child_count[i]; ++c) {
      const Sphere& ch = t.spheres[t.first_child[i] + c];
      t.spheres[i].r =
          std::max(t.spheres[i].r, (ch.center() - t.spheres[i].center()).norm() + ch.r);
    }
  t.rest_spheres = t.spheres;
  return t;
}

inline std::set<std::pair<int, int>> as_set(const std::vector<NodePair>& v) {
  std::set<std::pair<int, int>> s;
  for (const NodePair& p : v) s.insert({p.a, p.b});
  return s;
}

inline std::set<std::pair<int, int>> brute_force_leaf_overlaps(const SphereTree& a,
                                                               const SphereTree& b) {
  std::set<std::pair<int, int>> s;
  for (int i = 0; i < a.num_nodes(); ++i)
    if (a.is_leaf(i))
      for (int j = 0; j < b.num_nodes(); ++j)
        if (b.is_leaf(j) && overlap(a.spheres[i], b.spheres[j])) s.insert({i, j});
  return s;
}

}  // namespace icd::collision::testing
