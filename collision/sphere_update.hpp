#pragma once
/// Per-frame update of a sphere tree from the coarse nodes (paper 4.4, after
/// James & Pai's BD-trees). Cost: O(sum_i |V_i|), independent of the dense mesh.
#include <icd/collision/sphere_tree.hpp>
#include <icd/mesh/core/types.hpp>

namespace icd::collision {

/// How the radius follows the deformation.
enum class SphereUpdateMode {
  /// Paper 4.4: r = lambda * r_rest, lambda = max_j |x_j - c| / |X_j - C| over
  /// the associated nodes j (current / rest distance to the centre). A
  /// heuristic: not guaranteed to keep covering the surface.
  PaperRatio,
  /// James & Pai style bound: r = r_rest + max_j |u_j - mean(u)|. Conservative
  /// whenever every surface point under the rest sphere moves by a convex
  /// combination of the displacements u_j of the associated nodes (see
  /// associate_steering_nodes()).
  DisplacementBound,
};

/// Options of update_spheres().
struct SphereUpdateOptions {
  SphereUpdateMode mode = SphereUpdateMode::PaperRatio;
  double margin = 0.0;  ///< absolute amount added to every updated radius (model units, >= 0)
};

/// Updates tree.spheres from tree.rest_spheres and the associated coarse nodes:
/// centre c = C_rest + mean_j u_j with u_j = x_j - X_j (paper 4.4), radius per
/// `options.mode`, plus the margin. coarse_rest and coarse_positions: #Vc x 3.
/// Preconditions: the tree carries an association (associate_*_nodes) whose
/// indices are < #Vc; every node has at least one associated coarse node.
/// Throws ParameterError for missing association or mismatched sizes and
/// NumericalError (naming the node) if a sphere comes out non-finite.
void update_spheres(SphereTree& tree, const Eigen::Ref<const MatX3d>& coarse_rest,
                    const Eigen::Ref<const MatX3d>& coarse_positions,
                    const SphereUpdateOptions& options = {});

/// Grows every parent sphere, bottom-up, until it encloses its children's
/// spheres (turns a wrapped tree into a layered one, Guibas et al.): sphere
/// overlaps then never appear suddenly below a pruned pair, so a penalty
/// force computed from them is continuous in the positions. Only radii grow;
/// centres and leaves are unchanged.
void enclose_children(SphereTree& tree);

}  // namespace icd::collision
