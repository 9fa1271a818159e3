#pragma once
/// Barycentric embedding of the dense vertices in the coarse tet mesh: the
/// reference mapping against which the rigid links (paper 3.1) are measured.
/// Each dense vertex p is written as p = sum_j w_j x_j over the four nodes of
/// the coarse tet that contains it; a vertex outside every tet (the dense
/// surface pokes out of the coarse one) uses the tet whose smallest barycentric
/// coordinate is largest, i.e. a linear extrapolation of that tet's motion.
#include <Eigen/SparseCore>

#include <icd/mesh/core/types.hpp>

namespace icd::coupling {

/// The embedding as a sparse matrix W (#N x #M, four entries a row that sum to
/// 1), so that dense = W * coarse for any coarse positions (#M x 3).
struct BarycentricEmbedding {
  Eigen::SparseMatrix<double, Eigen::RowMajor> W;
  Eigen::VectorXi tet;  ///< #N: the coarse tet each vertex is expressed in
  int num_outside = 0;  ///< vertices not inside any tet (extrapolated)
};

/// Builds the embedding of P (#N x 3) in the tet mesh (V #M x 3, T #T x 4,
/// positively oriented). Uses a uniform grid over tet bounding boxes; cost
/// about O(N + #T). Throws ParameterError on an empty mesh or non-finite input.
BarycentricEmbedding build_barycentric_embedding(const Eigen::Ref<const MatX3d>& P,
                                                 const Eigen::Ref<const MatX3d>& V,
                                                 const Eigen::Ref<const MatX4i>& T);

/// dense_out = W * coarse_positions (#N x 3).
void apply(const BarycentricEmbedding& embedding, const Eigen::Ref<const MatX3d>& coarse_positions,
           Eigen::Ref<MatX3d> dense_out);

}  // namespace icd::coupling
