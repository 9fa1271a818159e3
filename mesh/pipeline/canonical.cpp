#include <icd/mesh/pipeline/canonical.hpp>

#include <algorithm>
#include <array>
#include <numeric>

namespace icd::mesh {

SurfaceMesh canonical_order(const SurfaceMesh& mesh, std::vector<int>* old_to_new) {
  const Eigen::Index nv = mesh.V.rows(), nf = mesh.F.rows();
  std::vector<int> order(static_cast<std::size_t>(nv));
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    for (int k = 0; k < 3; ++k)
      if (mesh.V(a, k) != mesh.V(b, k)) return mesh.V(a, k) < mesh.V(b, k);
    return false;
  });
  std::vector<int> map(static_cast<std::size_t>(nv));
  SurfaceMesh out;
  out.V.resize(nv, 3);
  for (Eigen::Index i = 0; i < nv; ++i) {
    out.V.row(i) = mesh.V.row(order[static_cast<std::size_t>(i)]);
    map[static_cast<std::size_t>(order[static_cast<std::size_t>(i)])] = static_cast<int>(i);
  }
  std::vector<std::array<int, 3>> faces(static_cast<std::size_t>(nf));
  for (Eigen::Index f = 0; f < nf; ++f) {
    std::array<int, 3> t{map[static_cast<std::size_t>(mesh.F(f, 0))],
                         map[static_cast<std::size_t>(mesh.F(f, 1))],
                         map[static_cast<std::size_t>(mesh.F(f, 2))]};
    std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
    faces[static_cast<std::size_t>(f)] = t;
  }
  std::sort(faces.begin(), faces.end());
  out.F.resize(nf, 3);
  for (Eigen::Index f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) out.F(f, k) = faces[static_cast<std::size_t>(f)][static_cast<std::size_t>(k)];
  if (old_to_new) *old_to_new = std::move(map);
  return out;
}

}  // namespace icd::mesh
