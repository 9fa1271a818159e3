#pragma once
// The clamped-beam model of the FEM experiments (fem_realtime,
// fem_frequency_tracking, ab_previous): StVK, E = 1e6 Pa, the default Poisson
// ratio and density, gravity along -z, Rayleigh alpha = 1 s^-1, every node at
// x = 0 fixed. Header-only so that ab_previous/ab_variant.cpp can compile it
// against a previous commit's fem sources as well.
#include <vector>

#include <icd/fem/model.hpp>
#include <icd/mesh/core/types.hpp>

namespace icd::fem {

/// The model above on the tet mesh `m` (clamped where x < 1e-12), with its
/// element forces on `threads` threads.
inline Model clamped_stvk_model(const TetMesh& m, int threads = 1) {
  Material mat;
  mat.model = MaterialModel::StVK;
  mat.young = 1e6;
  ModelOptions mo;
  mo.gravity = {0, 0, -9.81};
  mo.damping = {1.0, 0.0};
  mo.forces.num_threads = threads;
  Model model(m.V, m.T, mat, mo);
  std::vector<int> fixed;
  for (int i = 0; i < m.V.rows(); ++i)
    if (m.V(i, 0) < 1e-12) fixed.push_back(i);
  model.set_fixed_nodes(fixed);
  return model;
}

}  // namespace icd::fem
