#pragma once
// Shared helpers of the fem tests: small meshes, random states, materials.
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <icd/fem/material.hpp>
#include <icd/fem/model.hpp>
#include <icd/fem/tet_mesh_data.hpp>
#include <icd/mesh/core/primitives.hpp>

namespace icd::fem::test {

inline const std::vector<MaterialModel>& all_models() {
  static const std::vector<MaterialModel> models{MaterialModel::Linear, MaterialModel::Corotational,
                                                 MaterialModel::StVK,
                                                 MaterialModel::StableNeoHookean};
  return models;
}

inline TetMesh box(int nx, int ny, int nz, Eigen::Vector3d size = {1.0, 0.1, 0.1}) {
  BoxMeshOptions o;
  o.size = size;
  o.nx = nx;
  o.ny = ny;
  o.nz = nz;
  return make_box_tet_mesh(o);
}

inline TetMeshData box_data(int nx, int ny, int nz, Eigen::Vector3d size = {1.0, 0.1, 0.1}) {
  const TetMesh m = box(nx, ny, nz, size);
  return make_tet_mesh_data(m.V, m.T);
}

/// Uniform random matrix in [-1, 1] with a fixed seed.
inline MatX3d random_field(int rows, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  MatX3d r(rows, 3);
  for (int i = 0; i < rows; ++i)
    for (int c = 0; c < 3; ++c) r(i, c) = u(gen);
  return r;
}

inline Material material(MaterialModel model, double young = 1e6, double poisson = 0.3,
                         double density = 1000) {
  Material m;
  m.model = model;
  m.young = young;
  m.poisson = poisson;
  m.density = density;
  return m;
}

/// Test-name generator of parameterised tests over material models.
inline std::string model_name(const ::testing::TestParamInfo<MaterialModel>& param_info) {
  return to_string(param_info.param);
}

/// Cantilever 1.0 x 0.1 x 0.1 m on a (10 r) x r x r-cell structured mesh,
/// clamped (all nodes fixed) at x = 0, optionally under gravity along -z.
inline Model cantilever(int r, const Material& mat, double gravity = 9.81,
                        RayleighDamping damping = {}, int num_threads = 1) {
  const TetMesh m = box(10 * r, r, r);
  ModelOptions o;
  o.gravity = {0.0, 0.0, -gravity};
  o.damping = damping;
  o.forces.num_threads = num_threads;
  Model model(m.V, m.T, mat, o);
  std::vector<int> fixed;
  for (int i = 0; i < m.V.rows(); ++i)
    if (m.V(i, 0) < 1e-12) fixed.push_back(i);
  model.set_fixed_nodes(fixed);
  return model;
}

/// Mean z displacement of the nodes at x = L = 1 m.
inline double tip_deflection(const Model& model, const MatX3d& x) {
  double sum = 0;
  int count = 0;
  for (int i = 0; i < model.num_nodes(); ++i)
    if (model.mesh().rest_positions(i, 0) > 1.0 - 1e-12) {
      sum += x(i, 2) - model.mesh().rest_positions(i, 2);
      ++count;
    }
  return sum / count;
}

/// A rotation about a generic axis by a large angle.
inline Eigen::Matrix3d some_rotation(double angle = 2.1) {
  return Eigen::AngleAxisd(angle, Eigen::Vector3d(1.0, -2.0, 0.5).normalized()).toRotationMatrix();
}

}  // namespace icd::fem::test
