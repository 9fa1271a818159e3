#pragma once
/// Stage 3 of the preprocessing pipeline (issue 4): the coarse tetrahedral
/// mesh of a closed surface, with CGAL's 3D mesh generator (Mesh_3, polyhedral
/// domain), Delaunay refinement with quality bounds, then sliver perturbation
/// and exudation. Its boundary nodes are the reduced coordinates Q (paper 3.1).
#include <icd/mesh/core/types.hpp>
#include <icd/mesh/pipeline/tet_quality.hpp>

namespace icd::mesh {

/// Options of tetrahedralize_surface(). The element size is cell_size when
/// > 0; otherwise it is searched so that the mesh has about target_tets tets.
struct TetrahedralizeOptions {
  int target_tets = 2000;         ///< wanted number of tets (used when cell_size == 0)
  double count_tolerance = 0.25;  ///< accept |#tets / target - 1| <= this
  int max_size_iterations = 5;    ///< meshing passes of the size search (not optimised)
  double cell_size = 0.0;  ///< upper bound of tet circumradius (model units); 0: from target_tets
  double facet_size_factor = 1.0;      ///< facet size = factor * cell size
  double facet_distance_factor = 0.1;  ///< facet distance bound = factor * cell size
  double facet_angle_deg = 25.0;       ///< lower bound of surface triangle angles (<= 30)
  double radius_edge_bound = 3.0;  ///< cell radius-edge ratio bound (>= 2 guarantees termination)
  bool perturb = true;             ///< CGAL perturb_mesh_3 against slivers
  bool exude = true;               ///< CGAL exude_mesh_3 against slivers
  double sliver_bound_deg = 10.0;  ///< dihedral angle targeted by perturb/exude
  unsigned random_seed = 0;        ///< CGAL default random generator seed (determinism)
};

/// Result of tetrahedralize_surface().
struct TetrahedralizeResult {
  TetMesh mesh;  ///< positive tets, outward boundary F, every vertex used
  TetQuality quality;
  double cell_size = 0;  ///< cell size of the pass that was kept
  int passes = 0;        ///< meshing passes run (size search + the final optimised one)
};

/// Tetrahedralizes the region bounded by `surface` (closed, outward-oriented,
/// no self-intersection: the output of repair_surface()/simplify_surface()).
/// Deterministic: CGAL's default random generator is reset to random_seed
/// before each pass and the meshing runs sequentially without time limits.
/// Throws ParameterError on bad options, InputError when the surface is not
/// closed, the mesher produces no tet, or the tet boundary is not a closed
/// manifold surface (Mesh_3 runs with its manifold option, so this is a safeguard).
TetrahedralizeResult tetrahedralize_surface(const SurfaceMesh& surface,
                                            const TetrahedralizeOptions& options = {});

}  // namespace icd::mesh
