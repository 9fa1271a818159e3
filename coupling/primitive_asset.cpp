#include <icd/coupling/primitive_asset.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <vector>

#include <Eigen/Geometry>

#include <icd/collision/node_association.hpp>
#include <icd/collision/octree_tree.hpp>
#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/primitives.hpp>

namespace icd::coupling {
namespace {

// Drops unreferenced nodes of a tet mesh and recomputes its boundary.
TetMesh compact(const MatX3d& V, const std::vector<Eigen::Vector4i>& tets) {
  std::vector<int> map(V.rows(), -1);
  int n = 0;
  for (const auto& t : tets)
    for (int k = 0; k < 4; ++k)
      if (map[t[k]] < 0) map[t[k]] = n++;
  TetMesh m;
  m.V.resize(n, 3);
  for (int i = 0; i < V.rows(); ++i)
    if (map[i] >= 0) m.V.row(map[i]) = V.row(i);
  m.T.resize(static_cast<Eigen::Index>(tets.size()), 4);
  for (size_t e = 0; e < tets.size(); ++e)
    for (int k = 0; k < 4; ++k) m.T(e, k) = map[tets[e][k]];
  m.F = boundary_faces(m.T);
  return m;
}

}  // namespace

void build_octree_spheres(AssetBundle& a, int depth) {
  collision::OctreeTreeOptions to;
  to.levels = depth + 1;
  a.spheres = collision::build_octree_tree(a.dense.V, a.dense.F, to);
  std::vector<int> candidates(a.surface_nodes.data(),
                              a.surface_nodes.data() + a.surface_nodes.size());
  collision::associate_nearest_nodes(a.spheres, a.coarse.V, {}, candidates);
}

namespace {

void finish_asset(AssetBundle& a, int depth) {
  a.surface_nodes = boundary_nodes(a.coarse.F);
  a.links = build_rigid_links(a.dense.V, a.coarse.V, a.surface_nodes);
  build_octree_spheres(a, depth);
}

}  // namespace

AssetBundle make_primitive_asset(const PrimitiveSpec& spec, int depth) {
  AssetBundle a;
  if (spec.type == "box") {
    const Eigen::Vector3d half = spec.extent / 2;
    a.dense = make_box_surface(-half, half);
    // Refine the 12-triangle box into an icosphere-like density: subdivide
    // each face midpoint-wise `subdivisions` times (positions stay planar).
    for (int s = 0; s < spec.subdivisions; ++s) {
      std::vector<Eigen::Vector3d> v;
      for (int i = 0; i < a.dense.V.rows(); ++i) v.push_back(a.dense.V.row(i).transpose());
      std::map<std::pair<int, int>, int> mid;
      auto midpoint = [&](int p, int q) {
        const auto key = std::minmax(p, q);
        auto it = mid.find(key);
        if (it != mid.end()) return it->second;
        v.push_back((v[p] + v[q]) / 2);
        const int id = static_cast<int>(v.size()) - 1;
        mid.emplace(key, id);
        return id;
      };
      MatX3i F(4 * a.dense.F.rows(), 3);
      for (int f = 0; f < a.dense.F.rows(); ++f) {
        const int p = a.dense.F(f, 0), q = a.dense.F(f, 1), r = a.dense.F(f, 2);
        const int pq = midpoint(p, q), qr = midpoint(q, r), rp = midpoint(r, p);
        F.row(4 * f) << p, pq, rp;
        F.row(4 * f + 1) << q, qr, pq;
        F.row(4 * f + 2) << r, rp, qr;
        F.row(4 * f + 3) << pq, qr, rp;
      }
      a.dense.V.resize(static_cast<Eigen::Index>(v.size()), 3);
      for (size_t i = 0; i < v.size(); ++i) a.dense.V.row(i) = v[i].transpose();
      a.dense.F = F;
    }
    BoxMeshOptions bo;
    bo.min_corner = -half;
    bo.size = spec.extent;
    const double cell = spec.extent.maxCoeff() / spec.cells;
    bo.nx = std::max(1, static_cast<int>(std::round(spec.extent.x() / cell)));
    bo.ny = std::max(1, static_cast<int>(std::round(spec.extent.y() / cell)));
    bo.nz = std::max(1, static_cast<int>(std::round(spec.extent.z() / cell)));
    a.coarse = make_box_tet_mesh(bo);
  } else {
    a.dense = make_icosphere(spec.subdivisions, spec.radius);
    // Coarse ball: the tets of a structured grid whose centroid lies inside
    // the sphere. Its surface nodes stay within one cell of the sphere.
    const int n = std::max(2, spec.cells);
    BoxMeshOptions bo;
    bo.min_corner = Eigen::Vector3d::Constant(-spec.radius);
    bo.size = Eigen::Vector3d::Constant(2 * spec.radius);
    bo.nx = bo.ny = bo.nz = n;
    const TetMesh grid = make_box_tet_mesh(bo);
    std::vector<Eigen::Vector4i> keep;
    for (int e = 0; e < grid.T.rows(); ++e) {
      Eigen::RowVector3d c = Eigen::RowVector3d::Zero();
      for (int k = 0; k < 4; ++k) c += grid.V.row(grid.T(e, k)) / 4.0;
      if (c.norm() <= spec.radius) keep.push_back(grid.T.row(e).transpose());
    }
    if (keep.empty()) throw ParameterError("primitive sphere: too few cells for a coarse mesh");
    a.coarse = compact(grid.V, keep);
  }
  finish_asset(a, depth);
  return a;
}

Eigen::Matrix3d rotation_matrix(const Eigen::Vector3d& rotation_deg) {
  const double d2r = std::numbers::pi / 180.0;
  return (Eigen::AngleAxisd(rotation_deg.z() * d2r, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(rotation_deg.y() * d2r, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(rotation_deg.x() * d2r, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

void place_asset(AssetBundle& a, const Placement& spec) {
  const Eigen::RowVector3d lo = a.dense.V.colwise().minCoeff(), hi = a.dense.V.colwise().maxCoeff();
  const Eigen::RowVector3d centre = (lo + hi) / 2;
  const double longest = (hi - lo).maxCoeff();
  const double s = spec.size > 0 ? spec.size / longest : 1.0;
  const Eigen::Matrix3d R = rotation_matrix(spec.rotation_deg);
  const Eigen::RowVector3d pos = spec.position.transpose();
  auto map_points = [&](MatX3d& P) {
    P = (((P.rowwise() - centre) * s) * R.transpose()).rowwise() + pos;
  };
  map_points(a.dense.V);
  map_points(a.coarse.V);
  // Links store coefficients in the local frame of their three nodes: a
  // rotation and translation leave them unchanged, a scale multiplies them.
  a.links.coeffs *= s;
  for (auto* spheres : {&a.spheres.spheres, &a.spheres.rest_spheres})
    for (collision::Sphere& sp : *spheres) {
      const Eigen::Vector3d c = R * ((sp.center() - centre.transpose()) * s) + spec.position;
      sp = {c.x(), c.y(), c.z(), sp.r * s};
    }
  for (double& d : a.spheres.assoc_rest_dist) d *= s;
}

}  // namespace icd::coupling
