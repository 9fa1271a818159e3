#include <icd/collision/sphere_tree.hpp>

#include <cmath>
#include <string>

#include <icd/mesh/core/error.hpp>

namespace icd::collision {
namespace {

[[noreturn]] void fail(const std::string& what) { throw InputError("sphere tree: " + what); }

bool finite_sphere(const Sphere& s) {
  return std::isfinite(s.x) && std::isfinite(s.y) && std::isfinite(s.z) && std::isfinite(s.r) &&
         s.r >= 0.0;
}

}  // namespace

void validate(const SphereTree& tree) {
  const std::size_t n = tree.spheres.size();
  if (n == 0) fail("no nodes");
  if (tree.rest_spheres.size() != n)
    fail("rest_spheres has " + std::to_string(tree.rest_spheres.size()) + " entries, expected " +
         std::to_string(n));
  if (tree.first_child.size() != n)
    fail("first_child has " + std::to_string(tree.first_child.size()) + " entries, expected " +
         std::to_string(n));
  if (tree.child_count.size() != n)
    fail("child_count has " + std::to_string(tree.child_count.size()) + " entries, expected " +
         std::to_string(n));
  if (tree.level.size() != n)
    fail("level has " + std::to_string(tree.level.size()) + " entries, expected " +
         std::to_string(n));
  if (tree.level_offset.size() < 2) fail("level_offset needs at least 2 entries");
  if (tree.level_offset.front() != 0 || tree.level_offset.back() != static_cast<int32_t>(n))
    fail("level_offset must start at 0 and end at #nodes");
  if (tree.level[0] != 0) fail("node 0 (root) must be at level 0");
  for (std::size_t l = 0; l + 1 < tree.level_offset.size(); ++l) {
    const int32_t a = tree.level_offset[l], b = tree.level_offset[l + 1];
    if (b <= a) fail("level " + std::to_string(l) + " is empty");
    for (int32_t i = a; i < b; ++i)
      if (tree.level[i] != static_cast<int32_t>(l))
        fail("node " + std::to_string(i) + " has level " + std::to_string(tree.level[i]) +
             " but lies in the range of level " + std::to_string(l));
  }
  if (tree.level_offset[1] != 1) fail("level 0 must hold exactly the root");
  int32_t expected_next = 1;  // breadth-first: children blocks follow each other
  for (std::size_t i = 0; i < n; ++i) {
    const std::string node = "node " + std::to_string(i);
    if (!finite_sphere(tree.spheres[i]))
      fail(node + ": sphere has a non-finite value or negative radius");
    if (!finite_sphere(tree.rest_spheres[i]))
      fail(node + ": rest sphere has a non-finite value or negative radius");
    const int32_t fc = tree.first_child[i], cc = tree.child_count[i];
    if (cc < 0) fail(node + ": negative child_count");
    if (cc == 0) {
      if (fc != -1) fail(node + ": leaf must have first_child -1");
      continue;
    }
    if (fc != expected_next)
      fail(node + ": first_child " + std::to_string(fc) + " breaks breadth-first order (expected " +
           std::to_string(expected_next) + ")");
    if (fc + cc > static_cast<int32_t>(n)) fail(node + ": children run past the last node");
    for (int32_t c = fc; c < fc + cc; ++c)
      if (tree.level[c] != tree.level[i] + 1)
        fail(node + ": child " + std::to_string(c) + " is not one level deeper");
    expected_next = fc + cc;
  }
  if (expected_next != static_cast<int32_t>(n))
    fail("nodes " + std::to_string(expected_next) + ".. have no parent");

  if (tree.assoc_offset.empty()) {
    if (!tree.assoc_nodes.empty() || !tree.assoc_rest_dist.empty())
      fail("assoc_nodes given without assoc_offset");
    return;
  }
  if (tree.assoc_offset.size() != n + 1) fail("assoc_offset must have #nodes + 1 entries");
  if (tree.assoc_offset[0] != 0) fail("assoc_offset must start at 0");
  for (std::size_t i = 0; i < n; ++i)
    if (tree.assoc_offset[i + 1] < tree.assoc_offset[i])
      fail("node " + std::to_string(i) + ": assoc_offset decreases");
  if (tree.assoc_offset.back() != static_cast<int32_t>(tree.assoc_nodes.size()))
    fail("assoc_offset.back() must equal the size of assoc_nodes");
  if (tree.assoc_rest_dist.size() != tree.assoc_nodes.size())
    fail("assoc_rest_dist and assoc_nodes differ in size");
  for (std::size_t i = 0; i < n; ++i)
    for (int32_t k = tree.assoc_offset[i]; k < tree.assoc_offset[i + 1]; ++k) {
      if (tree.assoc_nodes[k] < 0)
        fail("node " + std::to_string(i) + ": negative associated coarse node index");
      if (!std::isfinite(tree.assoc_rest_dist[k]) || tree.assoc_rest_dist[k] < 0.0)
        fail("node " + std::to_string(i) + ": invalid rest distance to an associated node");
    }
}

void build_topology(SphereTree& tree, const std::vector<int32_t>& parent) {
  const std::size_t n = tree.spheres.size();
  if (n == 0) throw ParameterError("build_topology: no nodes");
  if (parent.size() != n)
    throw ParameterError("build_topology: parent has " + std::to_string(parent.size()) +
                         " entries, expected " + std::to_string(n));
  if (parent[0] != -1) throw ParameterError("build_topology: node 0 must be the root (parent -1)");
  tree.first_child.assign(n, -1);
  tree.child_count.assign(n, 0);
  tree.level.assign(n, 0);
  for (std::size_t i = 1; i < n; ++i) {
    const int32_t p = parent[i];
    if (p < 0 || p >= static_cast<int32_t>(i))
      throw ParameterError("build_topology: node " + std::to_string(i) + " has parent " +
                           std::to_string(p) + ", which does not precede it");
    if (p < parent[i - 1])
      throw ParameterError("build_topology: node " + std::to_string(i) +
                           " breaks breadth-first order (parents must not decrease)");
    if (tree.child_count[p] == 0) tree.first_child[p] = static_cast<int32_t>(i);
    ++tree.child_count[p];
    tree.level[i] = tree.level[p] + 1;
    if (tree.level[i] < tree.level[i - 1])
      throw ParameterError("build_topology: node " + std::to_string(i) + " breaks level order");
  }
  tree.level_offset.clear();
  for (std::size_t i = 0; i < n; ++i)
    while (static_cast<int32_t>(tree.level_offset.size()) <= tree.level[i])
      tree.level_offset.push_back(static_cast<int32_t>(i));
  tree.level_offset.push_back(static_cast<int32_t>(n));
  if (tree.rest_spheres.size() != n) tree.rest_spheres = tree.spheres;
}

void truncate_levels(SphereTree& tree, int max_level) {
  if (max_level < 0)
    throw ParameterError("truncate_levels: max_level must be >= 0, got " +
                         std::to_string(max_level));
  if (max_level + 1 >= tree.num_levels()) return;
  const int32_t keep = tree.level_offset[max_level + 1];
  tree.spheres.resize(keep);
  tree.rest_spheres.resize(keep);
  tree.first_child.resize(keep);
  tree.child_count.resize(keep);
  tree.level.resize(keep);
  tree.level_offset.resize(max_level + 2);
  for (int32_t i = tree.level_offset[max_level]; i < keep; ++i) {
    tree.first_child[i] = -1;
    tree.child_count[i] = 0;
  }
  if (!tree.assoc_offset.empty()) {
    tree.assoc_offset.resize(keep + 1);
    tree.assoc_nodes.resize(tree.assoc_offset.back());
    tree.assoc_rest_dist.resize(tree.assoc_offset.back());
  }
}

std::vector<int32_t> parents(const SphereTree& tree) {
  std::vector<int32_t> p(tree.spheres.size(), -1);
  for (int i = 0; i < tree.num_nodes(); ++i)
    for (int32_t c = 0; c < tree.child_count[i]; ++c) p[tree.first_child[i] + c] = i;
  return p;
}

}  // namespace icd::collision
