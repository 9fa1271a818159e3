#pragma once
/// Vertex- and face-order independence of the preprocessing (issue 30 item
/// 8): every stage after repair works on the surface in a canonical order
/// that depends on its geometry only, so the same triangles listed in another
/// order give the same coarse mesh and sphere tree (CGAL's edge-collapse queue
/// breaks cost ties by edge index, the Mesh_3 seeding takes the first vertex
/// of each voxel, and the sphere builder's sums round differently in another
/// order: each leaked the input order before).
#include <vector>

#include <icd/mesh/core/types.hpp>

namespace icd::mesh {

/// `mesh` with its vertices sorted by coordinates (x, then y, then z; exact
/// duplicates keep their relative order), each face rotated so that its
/// smallest new index comes first (orientation kept), and the faces sorted.
/// `old_to_new` (optional) receives the vertex map. Unused vertices are kept.
SurfaceMesh canonical_order(const SurfaceMesh& mesh, std::vector<int>* old_to_new = nullptr);

}  // namespace icd::mesh
