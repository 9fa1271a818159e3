#pragma once
/// A post-pass on a coarse tet mesh for explicit FEM (issue 30, item 5): the
/// stable step of a lumped-mass mesh is set by its lightest, stiffest node,
/// and on Mesh_3 meshes of 1,500-2,000 tets that is a surface node held by
/// two or three tiny tets (a thin feature one tet thick: the dragon's worst
/// node has 0.3 % of a mean node's mass and sets a step 0.07 x that of
/// near-regular tets). The pass collapses such nodes into a neighbour, worst
/// first, while the result stays a valid mesh with a closed manifold boundary.
/// Plain Eigen: no CGAL.
#include <icd/mesh/core/types.hpp>

namespace icd::mesh {

/// Options of raise_stable_step().
struct StepCleanupOptions {
  /// Collapse nodes while the largest node frequency exceeds that of
  /// near-regular tets of the same mean volume / target_ratio (0: off). The
  /// node frequency (the 3x3 diagonal block of M^-1 K, linear elasticity) is
  /// a lower bound of the mesh's largest eigenfrequency and within 1 % of it
  /// on the bunny and dragon, whose top modes sit on single nodes.
  double target_ratio = 0.6;
  double poisson = 0.3;  ///< Poisson ratio of the node frequencies (the ratio depends on it only)
  /// A surface node moves at most this fraction of the bounding-box diagonal
  /// (the length of the boundary edge it is collapsed along).
  double max_shift = 0.02;
  /// The enclosed volume changes by at most this fraction in all.
  double max_volume_change = 0.01;
  /// Every tet a collapse changes keeps its smallest dihedral angle at least
  /// min(this, the mesh's smallest before the pass), in degrees.
  double min_dihedral_deg = 12.0;
  /// Then the tets whose smallest dihedral angle is below this (degrees; 0:
  /// off) go too, the smallest first, by the same moves of one of their
  /// nodes under the same bounds, where every tet the move changes gets a
  /// larger smallest angle than the tet it replaces and no node frequency
  /// rises above max(the target's, the mesh's largest): the step is not
  /// traded for the angle. The target (issue 30, item 5).
  double dihedral_target_deg = 12.0;
  int max_collapses = 2000;
  /// Then the tets still below dihedral_target_deg get one of their nodes
  /// relocated (connectivity kept: an interior node freely, a surface node
  /// along the boundary, within max_shift), where the smallest angle of the
  /// node's tets rises and no node frequency rises above max(the target's,
  /// the mesh's largest): at most this many sweeps over them (0: off).
  int max_relocation_sweeps = 4;
  /// Before and after the relocations, the tets still below
  /// dihedral_target_deg are replaced by flips that keep the region (a 2-3
  /// flip across a face, the removal of an interior edge whose ring holds 3
  /// to 7 tets: 3-2, 4-4, 5-6, ...) where every new tet has a larger smallest
  /// angle than the sliver, or, for a sliver with a face on the boundary,
  /// dropped (the surface then runs over its other faces: a flat sliver
  /// holds next to no volume) under the surface, volume and topology bounds
  /// of the collapses; no node frequency rises above max(the target's, the
  /// mesh's largest). false: off.
  bool flips = true;
  /// The dihedral phases may change the enclosed volume by this fraction
  /// more, counted from where the step phase left it (that phase may use all
  /// of max_volume_change): moving or dropping a surface sliver costs a
  /// little volume, and the step phase used up the whole 1 % on 6 of the 7
  /// corpus meshes left below 12 deg.
  double dihedral_volume_change = 0.005;
  /// Last, and only when tets below dihedral_target_deg remain after all the
  /// phases above (a mesh that meets the target is left as they left it):
  /// the nodes of those tets are moved once more, a surface node now also off
  /// the boundary, by at most this fraction of the bounding-box diagonal from
  /// the boundary as it was before this phase (the coarse surface's distance
  /// to the dense one grows by at most as much), under the same acceptance
  /// rule as the relocations, in up to 2 x max_relocation_sweeps sweeps
  /// (off with them); then flips once more. For parts one tet thick (knots,
  /// tubes): their last slivers have all four nodes on the surface, which the
  /// tangential relocation cannot lift. 0: off.
  double max_off_surface = 0.005;
};

/// What raise_stable_step() did.
struct StepCleanupReport {
  int collapses = 0;       ///< nodes removed
  int stuck = 0;           ///< nodes above the target that no valid collapse improved
  double ratio_before = 0; ///< node-frequency estimate of the stable-step ratio before the pass
  double ratio_after = 0;  ///< ... and after it
  double volume_change = 0;  ///< relative change of the enclosed volume
  int dihedral_collapses = 0;      ///< nodes removed by the dihedral phase
  double min_dihedral_before = 0;  ///< smallest dihedral angle (deg) before the dihedral phase
  double min_dihedral_after = 0;   ///< ... and after it (0 when the pass did not run)
  int relocations = 0;             ///< node moves of the relocation phase
  int flips = 0;                   ///< flips of the dihedral phases (2-3, 3-2, 4-4, ...)
  int drops = 0;                   ///< surface slivers dropped by the dihedral phases
  int off_surface = 0;             ///< node moves of the last phase (max_off_surface)
};

/// Collapses the nodes that limit the stable step, then those of the tets
/// below the dihedral target, then relocates nodes of the tets still below it
/// (see StepCleanupOptions), in place: `mesh` (positive tets, F its boundary, a closed manifold) keeps
/// positive tets, a closed manifold boundary of the same Euler characteristic
/// and components, and every node used; F is recomputed. Deterministic.
StepCleanupReport raise_stable_step(TetMesh& mesh, const StepCleanupOptions& options = {});

/// Largest circular eigenfrequency (rad/s) of the near-regular BCC block with
/// mean tet volume `mean_volume`, the scene's default density and Young's
/// modulus and `poisson` (fem_step.hpp's ideal), for the node frequencies of
/// raise_stable_step().
double ideal_omega(double mean_volume, double poisson);

}  // namespace icd::mesh
