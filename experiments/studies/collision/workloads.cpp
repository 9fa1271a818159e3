#include "experiments/studies/collision/workloads.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include <icd/collision/node_association.hpp>
#include <icd/collision/octree_tree.hpp>
#include <icd/config.hpp>
#include <icd/mesh/core/primitives.hpp>
#include <icd/mesh/io/surface_reader.hpp>

namespace icd::collision::experiments {

std::string data_path(const std::string& file) {
  const char* env = std::getenv("ICD_DATA_DIR");
  return std::string(env ? env : ICD_DATA_DIR) + "/" + file;
}

namespace {

Object finish(std::string name, SurfaceMesh m, const Eigen::Vector3d& center, double target_side,
              int levels, int coarse_nodes) {
  const Eigen::RowVector3d lo = m.V.colwise().minCoeff(), hi = m.V.colwise().maxCoeff();
  const double s = target_side / (hi - lo).maxCoeff();
  const Eigen::RowVector3d mid = 0.5 * (lo + hi);
  for (int i = 0; i < m.V.rows(); ++i) m.V.row(i) = (m.V.row(i) - mid) * s + center.transpose();
  Object o;
  o.name = std::move(name);
  o.dense = std::move(m);
  const int step = std::max<int>(1, static_cast<int>(o.dense.V.rows() / std::max(coarse_nodes, 1)));
  std::vector<int> rows;
  for (int i = 0; i < o.dense.V.rows(); i += step) rows.push_back(i);
  o.coarse_rest.resize(static_cast<int>(rows.size()), 3);
  for (std::size_t k = 0; k < rows.size(); ++k)
    o.coarse_rest.row(static_cast<int>(k)) = o.dense.V.row(rows[k]);
  OctreeTreeOptions opt;
  opt.levels = levels;
  o.tree = build_octree_tree(o.dense.V, o.dense.F, opt);
  NodeAssociationOptions ao;
  ao.k_nearest = 4;
  ao.max_nodes = 16;
  associate_nearest_nodes(o.tree, o.coarse_rest, ao);
  return o;
}

}  // namespace

Object load_object(const std::string& file, const Eigen::Vector3d& center, int levels,
                   int coarse_nodes) {
  return finish(file, read_surface_mesh(data_path(file)), center, 2.0, levels, coarse_nodes);
}

Object icosphere_object(int subdivisions, double radius, const Eigen::Vector3d& center,
                        int levels) {
  return finish("icosphere", make_icosphere(subdivisions, radius), center, 2.0 * radius, levels,
                800);
}

MatX3d deform(const MatX3d& X, double amplitude, double t) {
  MatX3d x(X.rows(), 3);
  for (int i = 0; i < X.rows(); ++i) {
    x(i, 0) = X(i, 0) + amplitude * std::sin(3 * X(i, 1) + t);
    x(i, 1) = X(i, 1) + amplitude * std::sin(2 * X(i, 2) + 1.3 * t);
    x(i, 2) = X(i, 2) + amplitude * std::sin(2.5 * X(i, 0) + 0.7 * t);
  }
  return x;
}

}  // namespace icd::collision::experiments
