#pragma once
/// Broad phase for scenes of many objects: sweep-and-prune on the root
/// spheres, giving the object pairs worth a sphere-tree traversal.
#include <utility>
#include <vector>

#include <icd/collision/sphere_tree.hpp>

namespace icd::collision {

/// Object pairs (i, j), i < j, whose bounding spheres overlap (closed balls),
/// found by sorting the spheres' x intervals and sweeping (O(n log n + k)
/// for k interval overlaps). Sorted lexicographically. Throws ParameterError
/// for a non-finite sphere or a negative radius (naming the object).
std::vector<std::pair<int, int>> sweep_and_prune(const std::vector<Sphere>& bounds);

/// The same by testing all n (n - 1) / 2 pairs: the oracle.
std::vector<std::pair<int, int>> all_pairs_overlapping(const std::vector<Sphere>& bounds);

/// The root spheres of several trees, in order (input of sweep_and_prune).
std::vector<Sphere> root_spheres(const std::vector<const SphereTree*>& trees);

}  // namespace icd::collision
