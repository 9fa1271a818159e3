#pragma once
// Independent checks shared by the pipeline tests (no CGAL).
#include <Eigen/Geometry>

#include <map>
#include <set>
#include <utility>

#include <icd/mesh/core/types.hpp>

namespace icd::mesh::test {

// Total signed volume enclosed by a closed surface (divergence theorem).
inline double enclosed_volume(const MatX3d& V, const MatX3i& F) {
  double vol = 0.0;
  for (int f = 0; f < F.rows(); ++f)
    vol += V.row(F(f, 0)).dot(V.row(F(f, 1)).cross(V.row(F(f, 2)))) / 6.0;
  return vol;
}

// Every directed edge appears once and its reverse once: closed, manifold
// along edges, consistently oriented.
inline bool closed_and_oriented(const MatX3i& F) {
  std::map<std::pair<int, int>, int> directed;
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) ++directed[{F(f, k), F(f, (k + 1) % 3)}];
  for (const auto& [e, n] : directed) {
    if (n != 1) return false;
    auto it = directed.find({e.second, e.first});
    if (it == directed.end() || it->second != 1) return false;
  }
  return true;
}

// Every vertex is used by some face.
inline bool all_vertices_used(int num_vertices, const int* idx, Eigen::Index n) {
  std::set<int> used(idx, idx + n);
  return static_cast<int>(used.size()) == num_vertices && *used.begin() == 0 &&
         *used.rbegin() == num_vertices - 1;
}

// Removes the faces listed in `drop`, keeping V.
inline SurfaceMesh without_faces(const SurfaceMesh& m, const std::set<int>& drop) {
  SurfaceMesh out;
  out.V = m.V;
  out.F.resize(m.F.rows() - static_cast<Eigen::Index>(drop.size()), 3);
  int k = 0;
  for (int f = 0; f < m.F.rows(); ++f)
    if (!drop.count(f)) out.F.row(k++) = m.F.row(f);
  return out;
}

}  // namespace icd::mesh::test
