#pragma once
/// Rigid links between the dense surface and the coarse tetrahedral mesh
/// (paper section 3.1-3.2, Eqs. 1-10).
///
/// Each dense vertex p is tied to three coarse surface nodes q0, q1, q2 (its
/// three closest, skipping coincident or collinear candidates). The link origin
/// O = sum_i alpha_i q_i (Eq. 1) uses the distance weights of Eq. 3 divided by
/// 2 * sum_i d_i: as printed in the paper they sum to 2, which would move O twice
/// as far as the object under a translation. The link vector p - O is stored as
/// its signed projections (Eqs. 7-8) onto the orthonormal frame of Eqs. 4-6,
///   e0 = n / |n|,  e1 = (q0 - q1) / |q0 - q1|,  e2 = a / |a|,
///   n = (q1 - q0) x (q2 - q0),  a = (q1 - q0) x n,
/// and re-expressed in the current frame at run time (Eqs. 9-10). The mapping
/// reproduces the dense mesh exactly under any rigid motion of the coarse nodes.
#include <cstdint>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <icd/mesh/core/types.hpp>

namespace icd::coupling {

/// #N x 3 node indices, row-major (one link per row).
using MatX3i32 = Eigen::Matrix<int32_t, Eigen::Dynamic, 3, Eigen::RowMajor>;

/// Options of build_rigid_links().
struct RigidLinkOptions {
  /// Two candidate nodes closer than this fraction of the coarse bounding-box
  /// diagonal are coincident; the later (farther) one is skipped.
  double coincident_tolerance = 1e-9;
  /// A candidate triangle (q0, q1, q2) is collinear when
  /// |(q1 - q0) x (q2 - q0)| < collinear_tolerance * (longest edge)^2,
  /// i.e. roughly when its smallest angle is below this many radians.
  double collinear_tolerance = 1e-3;
  /// Nearest candidates examined first; doubled until a valid triple is found.
  int initial_candidates = 16;
};

/// Precomputed rigid links of N dense vertices (paper Eqs. 1-8).
/// Row k of each matrix belongs to dense vertex k.
struct RigidLinks {
  /// #N x 3: indices q0, q1, q2 into the coarse node array (not into the
  /// surface-node list), ordered by increasing rest distance to the dense vertex
  /// (apart from skipped candidates).
  MatX3i32 nodes;
  /// #N x 3: origin weights alpha_i of Eq. 3 divided by 2 * sum d_i (each row sums to 1).
  MatX3d alpha;
  /// #N x 3: signed projections xi_i * |Pr_i| of the rest link p - O onto
  /// (e0, e1, e2) of Eq. 6 (model units).
  MatX3d coeffs;
  /// Number of rows the coarse position array must have (for checks at apply time).
  int32_t num_coarse_nodes = 0;

  int num_links() const { return static_cast<int>(nodes.rows()); }
};

/// Builds the links of the dense vertices P (#N x 3) to the coarse surface
/// nodes: `coarse_rest_positions` (#M x 3, every coarse node, rest state) and
/// `surface_nodes` (the reduced coordinates Q: indices into it, no repeats).
/// Nearest candidates come from a kd-tree over the surface nodes; ties in
/// distance are broken by the smaller node index, so the result is
/// deterministic. Throws ParameterError on bad options or out-of-range
/// indices, InputError when fewer than three non-collinear surface nodes exist
/// or a position is not finite.
RigidLinks build_rigid_links(const Eigen::Ref<const MatX3d>& P,
                             const Eigen::Ref<const MatX3d>& coarse_rest_positions,
                             const Eigen::Ref<const Eigen::VectorXi>& surface_nodes,
                             const RigidLinkOptions& options = {});

/// Evaluates the links (Eqs. 1, 9, 10): dense_out.row(k) = O_k + sum_i c_ki e_i
/// with the frame of the current coarse positions (#M x 3, M ==
/// links.num_coarse_nodes). dense_out must already have links.num_links() rows.
/// Convenience wrapper: builds a LinkEvaluator on the fly (hashes the node
/// triples and allocates ~70 bytes per link; measured 23-35 ns per dense vertex
/// in all, 0.6-0.9x the cost of apply_reference(), where a kept evaluator
/// costs 7-15 ns), so code that evaluates the same links every frame should keep a
/// LinkEvaluator (coupling/link_evaluator.hpp) instead. Degenerate frames use
/// the evaluator's fallback frame (no previous frame: see link_evaluator.hpp).
/// Throws ParameterError on a size mismatch, InputError on inconsistent links,
/// NumericalError when a linked coarse node is not finite.
void apply(const RigidLinks& links, const Eigen::Ref<const MatX3d>& coarse_positions,
           Eigen::Ref<MatX3d> dense_out);

/// The original one-link-at-a-time evaluation (Eigen 3-vectors, the frame
/// recomputed for every link), kept as the reference that LinkEvaluator is
/// tested and benchmarked against. Same contract as apply() except that the
/// links are not validated and for degenerate frames: an axis whose defining
/// vector is exactly zero stays zero
/// (Eigen's normalized()), so exactly collinear nodes drop the e0 and e2 terms
/// and coincident q0 == q1 collapse the vertex onto O; non-finite coarse
/// positions give non-finite output without an exception. No allocation.
void apply_reference(const RigidLinks& links, const Eigen::Ref<const MatX3d>& coarse_positions,
                     Eigen::Ref<MatX3d> dense_out);

/// The origin map of Eq. 1 as a sparse matrix A (#N x #M, row-major, three
/// entries alpha_ki per row at columns nodes(k, i)): O = A * coarse_positions.
Eigen::SparseMatrix<double, Eigen::RowMajor> origin_matrix(const RigidLinks& links);

/// Checks the internal consistency of `links` (sizes, index ranges, finite
/// values, weights summing to 1); throws InputError naming `what` and the first
/// bad row otherwise. Used after loading links from disk.
void validate(const RigidLinks& links, const char* what);

}  // namespace icd::coupling
