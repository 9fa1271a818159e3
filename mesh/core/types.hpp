#pragma once
/// Matrix types shared by every module (libigl conventions, row-major so that
/// one vertex or one element is contiguous in memory).
#include <Eigen/Core>

namespace icd {

/// #V x 3 vertex positions (metres, or model units for raw meshes).
using MatX3d = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
/// #F x 3 triangle vertex indices.
using MatX3i = Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>;
/// #T x 4 tetrahedron vertex indices.
using MatX4i = Eigen::Matrix<int, Eigen::Dynamic, 4, Eigen::RowMajor>;

/// A triangle surface mesh: V (#V x 3) and F (#F x 3), faces oriented
/// counter-clockwise seen from outside.
struct SurfaceMesh {
  MatX3d V;
  MatX3i F;
};

/// A tetrahedral mesh: V (#V x 3), T (#T x 4) with positive orientation
/// (det[v1-v0, v2-v0, v3-v0] > 0), and its boundary triangles F (#F x 3),
/// oriented outward.
struct TetMesh {
  MatX3d V;
  MatX4i T;
  MatX3i F;
};

}  // namespace icd
