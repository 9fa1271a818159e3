#pragma once

#include <set>
#include <vector>

#include <icd/collision/node_association.hpp>
#include <icd/coupling/asset_bundle.hpp>
#include <icd/mesh/core/primitives.hpp>

namespace icd::coupling {

/// A small but complete asset bundle for tests: an icosphere (`subdivisions`,
/// `radius`, centred at (0.5, 0.5, 0.5)) steered by a 2x2x2 box tet mesh of the
/// unit cube through rigid links, and a two-level sphere tree (root + 4
/// children) associated with the coarse surface nodes.
inline AssetBundle make_small_bundle(int subdivisions, double radius) {
  AssetBundle b;
  b.dense = make_icosphere(subdivisions, radius);
  b.dense.V.rowwise() += Eigen::RowVector3d(0.5, 0.5, 0.5);
  BoxMeshOptions o;
  o.size = {1, 1, 1};
  o.nx = o.ny = o.nz = 2;
  b.coarse = make_box_tet_mesh(o);
  const std::set<int> s(b.coarse.F.data(), b.coarse.F.data() + b.coarse.F.size());
  b.surface_nodes.resize(static_cast<Eigen::Index>(s.size()));
  int i = 0;
  for (int v : s) b.surface_nodes[i++] = v;
  b.links = build_rigid_links(b.dense.V, b.coarse.V, b.surface_nodes);
  collision::SphereTree& t = b.spheres;
  t.spheres = {{0.5, 0.5, 0.5, 0.9},
               {0.25, 0.5, 0.5, 0.5},
               {0.75, 0.5, 0.5, 0.5},
               {0.5, 0.25, 0.5, 0.5},
               {0.5, 0.75, 0.5, 0.5}};
  collision::build_topology(t, {-1, 0, 0, 0, 0});
  std::vector<int> cand(b.surface_nodes.data(), b.surface_nodes.data() + b.surface_nodes.size());
  collision::associate_nearest_nodes(t, b.coarse.V, {}, cand);
  return b;
}

}  // namespace icd::coupling
