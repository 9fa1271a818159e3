#pragma once
/// Small meshes generated in code, for tests, examples and benchmarks.
#include <icd/mesh/core/types.hpp>

namespace icd {

/// A single tetrahedron with vertices (0,0,0), (1,0,0), (0,1,0), (0,0,1).
TetMesh make_unit_tet();

/// Options of a structured tetrahedral box mesh.
struct BoxMeshOptions {
  Eigen::Vector3d min_corner{0.0, 0.0, 0.0};
  Eigen::Vector3d size{1.0, 0.1, 0.1};  ///< metres along x, y, z
  int nx = 10, ny = 1, nz = 1;          ///< cells along x, y, z (>= 1)
};

/// Structured box: nx*ny*nz cubes (cells of size/n), each split into 6 tets
/// (Kuhn / Freudenthal split, conforming across cells). Vertex (i,j,k) has
/// index i + (nx+1)*(j + (ny+1)*k). Tets are positively oriented; F is the
/// outward boundary. Throws ParameterError for non-positive counts or sizes.
TetMesh make_box_tet_mesh(const BoxMeshOptions& options);

/// Closed unit-radius icosphere centred at the origin, `subdivisions` times
/// subdivided icosahedron (20 * 4^s faces), outward-oriented.
SurfaceMesh make_icosphere(int subdivisions, double radius = 1.0);

/// Closed axis-aligned box surface [min, max] of 12 triangles, outward-oriented.
SurfaceMesh make_box_surface(const Eigen::Vector3d& min, const Eigen::Vector3d& max);

/// Closed torus around the z axis: major radius R, minor radius r,
/// nu x nv quads split into triangles, outward-oriented.
SurfaceMesh make_torus(double R, double r, int nu, int nv);

/// Outward boundary triangles of a positively oriented tet mesh T (#T x 4):
/// faces that belong to exactly one tet, ordered by (tet, local face).
MatX3i boundary_faces(const Eigen::Ref<const MatX4i>& T);

/// Sorted, distinct vertex indices used by the triangles F (#F x 3): for the
/// boundary F of a tet mesh, its surface nodes (the paper's reduced coordinates Q).
Eigen::VectorXi boundary_nodes(const Eigen::Ref<const MatX3i>& F);

/// Signed volume of every tet: det[v1-v0, v2-v0, v3-v0] / 6 (#T).
Eigen::VectorXd signed_tet_volumes(const Eigen::Ref<const MatX3d>& V,
                                   const Eigen::Ref<const MatX4i>& T);

}  // namespace icd
