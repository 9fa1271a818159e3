#pragma once
/// Distance and inside queries on a closed triangle mesh (our TriangleBvh and
/// CGAL's Side_of_triangle_mesh behind a small interface, so that CGAL stays inside
/// the .cpp files of mesh/).
#include <memory>

#include <Eigen/Core>

#include <icd/mesh/core/types.hpp>

namespace icd::mesh {

/// Returns a copy of `mesh` with every boundary loop (hole) closed by a
/// minimal-area triangulation (CGAL PMP triangulate_hole, compiled once in
/// the pipeline's repair.cpp as detail::fill_hole), so that inside tests are
/// well defined. Returns the input unchanged when it is closed.
/// Throws InputError when the mesh is empty, has out-of-range indices or
/// is not a valid polygon mesh. The only place where holes are closed in
/// mesh/spheres (used by both the builder and the evaluation).
SurfaceMesh close_holes(const SurfaceMesh& mesh);

/// Number of boundary edges of a triangle mesh F (#F x 3): directed edges
/// (a, b) with no twin (b, a). 0 for a closed, consistently oriented mesh.
int count_boundary_edges(const Eigen::Ref<const MatX3i>& F);

/// Exact distance, closest point and inside queries against a closed,
/// outward-oriented triangle mesh. Build once, query many (thread-compatible:
/// concurrent const queries are not guaranteed to be safe).
class MeshOracle {
 public:
  /// Builds the AABB tree. Precondition: `closed` is closed (see close_holes);
  /// throws InputError when it is empty or has a boundary.
  explicit MeshOracle(const SurfaceMesh& closed);
  ~MeshOracle();
  MeshOracle(const MeshOracle&) = delete;
  MeshOracle& operator=(const MeshOracle&) = delete;

  /// Unsigned distance from p to the surface (model units).
  double distance(const Eigen::Vector3d& p) const;
  /// Closest surface point to p.
  Eigen::Vector3d closest_point(const Eigen::Vector3d& p) const;
  /// True when p is strictly inside or on the boundary of the enclosed volume.
  bool inside(const Eigen::Vector3d& p) const;
  /// Signed distance: positive inside, negative outside.
  double signed_distance(const Eigen::Vector3d& p) const;
  /// The closed mesh the oracle was built on.
  const SurfaceMesh& mesh() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> m_impl;
};

}  // namespace icd::mesh
