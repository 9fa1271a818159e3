#include <icd/collision/node_association.hpp>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/triangle_geometry.hpp>

namespace icd::collision {
namespace {

// k nearest candidates to c (by squared distance), nearest first.
std::vector<std::pair<double, int>> nearest(const Eigen::Ref<const MatX3d>& P,
                                            const std::vector<int>& cand,
                                            const Eigen::Vector3d& c) {
  std::vector<std::pair<double, int>> d(cand.size());
  for (std::size_t k = 0; k < cand.size(); ++k)
    d[k] = {(P.row(cand[k]).transpose() - c).squaredNorm(), cand[k]};
  return d;
}

std::vector<int> candidate_list(const Eigen::Ref<const MatX3d>& P,
                                const std::vector<int>& candidates) {
  std::vector<int> cand = candidates;
  if (cand.empty()) {
    cand.resize(P.rows());
    std::iota(cand.begin(), cand.end(), 0);
  }
  if (cand.empty()) throw InputError("node association: no coarse node to associate with");
  for (int c : cand)
    if (c < 0 || c >= P.rows())
      throw ParameterError("node association: candidate node " + std::to_string(c) +
                           " out of range");
  for (int i = 0; i < P.rows(); ++i)
    if (!P.row(i).allFinite())
      throw InputError("node association: coarse node " + std::to_string(i) +
                       " has a non-finite position");
  return cand;
}

void store(SphereTree& tree, const Eigen::Ref<const MatX3d>& P,
           const std::vector<std::vector<int>>& sets) {
  tree.assoc_offset.assign(1, 0);
  tree.assoc_nodes.clear();
  tree.assoc_rest_dist.clear();
  for (int i = 0; i < tree.num_nodes(); ++i) {
    const Eigen::Vector3d c = tree.rest_spheres[i].center();
    for (int n : sets[i]) {
      tree.assoc_nodes.push_back(n);
      tree.assoc_rest_dist.push_back((P.row(n).transpose() - c).norm());
    }
    tree.assoc_offset.push_back(static_cast<int32_t>(tree.assoc_nodes.size()));
  }
}

}  // namespace

void associate_nearest_nodes(SphereTree& tree, const Eigen::Ref<const MatX3d>& coarse_rest,
                             const NodeAssociationOptions& options,
                             const std::vector<int>& candidates) {
  if (options.k_nearest < 1) throw ParameterError("NodeAssociationOptions::k_nearest must be >= 1");
  if (options.max_nodes < options.k_nearest)
    throw ParameterError("NodeAssociationOptions::max_nodes must be >= k_nearest");
  const std::vector<int> cand = candidate_list(coarse_rest, candidates);
  std::vector<std::vector<int>> sets(tree.num_nodes());
  for (int i = 0; i < tree.num_nodes(); ++i) {
    const Sphere& s = tree.rest_spheres[i];
    auto d = nearest(coarse_rest, cand, s.center());
    std::sort(d.begin(), d.end());
    const double r2 = s.r * s.r;
    for (std::size_t k = 0; k < d.size() && static_cast<int>(k) < options.max_nodes; ++k) {
      const bool inside = options.include_inside && d[k].first <= r2;
      if (static_cast<int>(k) < options.k_nearest || inside)
        sets[i].push_back(d[k].second);
      else
        break;
    }
  }
  store(tree, coarse_rest, sets);
}

void associate_steering_nodes(SphereTree& tree, const Eigen::Ref<const MatX3d>& coarse_rest,
                              const Eigen::Ref<const MatX3d>& dense_V,
                              const Eigen::Ref<const MatX3i>& dense_F,
                              const std::vector<int32_t>& steer_offset,
                              const std::vector<int32_t>& steer_nodes, int k_nearest) {
  if (k_nearest < 0) throw ParameterError("associate_steering_nodes: k_nearest must be >= 0");
  if (steer_offset.size() != static_cast<std::size_t>(dense_V.rows()) + 1)
    throw InputError(
        "associate_steering_nodes: steer_offset must have #dense vertices + 1 entries");
  if (steer_offset.front() != 0 || steer_offset.back() != static_cast<int32_t>(steer_nodes.size()))
    throw InputError("associate_steering_nodes: steer_offset must run from 0 to #steer_nodes");
  for (std::size_t v = 0; v + 1 < steer_offset.size(); ++v)
    if (steer_offset[v + 1] < steer_offset[v])
      throw InputError("associate_steering_nodes: steer_offset decreases at dense vertex " +
                       std::to_string(v));
  for (int32_t n : steer_nodes)
    if (n < 0 || n >= coarse_rest.rows())
      throw InputError("associate_steering_nodes: steering node " + std::to_string(n) +
                       " out of range");
  for (int f = 0; f < dense_F.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      if (dense_F(f, k) < 0 || dense_F(f, k) >= dense_V.rows())
        throw InputError("associate_steering_nodes: dense face " + std::to_string(f) +
                         " has an out-of-range vertex");
  const std::vector<int> cand = candidate_list(coarse_rest, {});

  // Triangle bounding boxes for a cheap rejection.
  const int nf = static_cast<int>(dense_F.rows());
  std::vector<Eigen::Vector3d> lo(nf), hi(nf);
  for (int f = 0; f < nf; ++f) {
    lo[f] = hi[f] = dense_V.row(dense_F(f, 0)).transpose();
    for (int k = 1; k < 3; ++k) {
      lo[f] = lo[f].cwiseMin(dense_V.row(dense_F(f, k)).transpose());
      hi[f] = hi[f].cwiseMax(dense_V.row(dense_F(f, k)).transpose());
    }
  }
  std::vector<std::vector<int>> sets(tree.num_nodes());
  std::vector<char> mark(coarse_rest.rows(), 0);
  for (int i = 0; i < tree.num_nodes(); ++i) {
    const Sphere& s = tree.rest_spheres[i];
    const Eigen::Vector3d c = s.center();
    std::vector<int>& set = sets[i];
    auto add = [&](int n) {
      if (!mark[n]) {
        mark[n] = 1;
        set.push_back(n);
      }
    };
    for (int f = 0; f < nf; ++f) {
      if ((lo[f] - c).maxCoeff() > s.r || (c - hi[f]).maxCoeff() > s.r) continue;
      const Eigen::Vector3d a = dense_V.row(dense_F(f, 0)).transpose(),
                            b = dense_V.row(dense_F(f, 1)).transpose(),
                            cc = dense_V.row(dense_F(f, 2)).transpose();
      if ((closest_point_on_triangle(c, a, b, cc) - c).squaredNorm() > s.r * s.r * (1.0 + 1e-12))
        continue;
      for (int k = 0; k < 3; ++k) {
        const int v = dense_F(f, k);
        for (int32_t j = steer_offset[v]; j < steer_offset[v + 1]; ++j) add(steer_nodes[j]);
      }
    }
    if (k_nearest > 0) {
      auto d = nearest(coarse_rest, cand, c);
      const std::size_t k = std::min<std::size_t>(k_nearest, d.size());
      std::partial_sort(d.begin(), d.begin() + k, d.end());
      for (std::size_t j = 0; j < k; ++j) add(d[j].second);
    }
    for (int n : set) mark[n] = 0;
  }
  store(tree, coarse_rest, sets);
}

}  // namespace icd::collision
