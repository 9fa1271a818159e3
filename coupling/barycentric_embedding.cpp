#include <icd/coupling/barycentric_embedding.hpp>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <vector>

#include <Eigen/Dense>

#include <icd/mesh/core/error.hpp>

namespace icd::coupling {
namespace {

// Barycentric coordinates of p in tet (a, b, c, d).
Eigen::Vector4d barycentric(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                            const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                            const Eigen::Vector3d& d) {
  Eigen::Matrix3d D;
  D << b - a, c - a, d - a;
  const Eigen::Vector3d l = D.partialPivLu().solve(p - a);
  return {1.0 - l.sum(), l[0], l[1], l[2]};
}

}  // namespace

BarycentricEmbedding build_barycentric_embedding(const Eigen::Ref<const MatX3d>& P,
                                                 const Eigen::Ref<const MatX3d>& V,
                                                 const Eigen::Ref<const MatX4i>& T) {
  if (T.rows() == 0 || V.rows() == 0)
    throw ParameterError("build_barycentric_embedding: the coarse tet mesh is empty");
  if (!P.allFinite() || !V.allFinite())
    throw ParameterError("build_barycentric_embedding: non-finite positions");
  if (T.minCoeff() < 0 || T.maxCoeff() >= V.rows())
    throw ParameterError("build_barycentric_embedding: tet index out of range");

  // Uniform grid over the tets' bounding boxes, about one tet per cell.
  const Eigen::RowVector3d lo = V.colwise().minCoeff(), hi = V.colwise().maxCoeff();
  const Eigen::RowVector3d ext = (hi - lo).cwiseMax(1e-12);
  const double cell =
      std::cbrt(ext.prod() / static_cast<double>(T.rows())) + 1e-12 * ext.maxCoeff();
  Eigen::Vector3i dims;
  for (int k = 0; k < 3; ++k)
    dims[k] = std::clamp(static_cast<int>(std::ceil(ext[k] / cell)), 1, 256);
  auto cell_of = [&](const Eigen::RowVector3d& x) {
    Eigen::Vector3i c;
    for (int k = 0; k < 3; ++k)
      c[k] = std::clamp(static_cast<int>(std::floor((x[k] - lo[k]) / ext[k] * dims[k])), 0,
                        dims[k] - 1);
    return c;
  };
  auto flat = [&](int i, int j, int k) { return i + dims[0] * (j + dims[1] * k); };
  std::vector<std::vector<int>> grid(static_cast<size_t>(dims.prod()));
  for (int t = 0; t < T.rows(); ++t) {
    Eigen::RowVector3d tlo = V.row(T(t, 0)), thi = tlo;
    for (int j = 1; j < 4; ++j) {
      tlo = tlo.cwiseMin(V.row(T(t, j)));
      thi = thi.cwiseMax(V.row(T(t, j)));
    }
    const Eigen::Vector3i a = cell_of(tlo), b = cell_of(thi);
    for (int k = a[2]; k <= b[2]; ++k)
      for (int j = a[1]; j <= b[1]; ++j)
        for (int i = a[0]; i <= b[0]; ++i) grid[flat(i, j, k)].push_back(t);
  }

  BarycentricEmbedding out;
  out.tet.resize(P.rows());
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(4 * P.rows());
  const int max_ring = std::max({dims[0], dims[1], dims[2]});
  for (int v = 0; v < P.rows(); ++v) {
    const Eigen::Vector3d p = P.row(v).transpose();
    const Eigen::Vector3i c = cell_of(P.row(v));
    int best = -1;
    double best_min = -1e300;
    Eigen::Vector4d best_w;
    // Search rings of cells around p's cell; stop once inside, or one ring
    // after the first candidate (an outside point's best tet is nearby).
    int stop_ring = max_ring;
    for (int r = 0; r <= stop_ring && r <= max_ring; ++r) {
      for (int k = c[2] - r; k <= c[2] + r; ++k)
        for (int j = c[1] - r; j <= c[1] + r; ++j)
          for (int i = c[0] - r; i <= c[0] + r; ++i) {
            if (i < 0 || j < 0 || k < 0 || i >= dims[0] || j >= dims[1] || k >= dims[2]) continue;
            if (std::max({std::abs(i - c[0]), std::abs(j - c[1]), std::abs(k - c[2])}) != r)
              continue;  // only the ring's shell
            for (int t : grid[flat(i, j, k)]) {
              const Eigen::Vector4d w =
                  barycentric(p, V.row(T(t, 0)), V.row(T(t, 1)), V.row(T(t, 2)), V.row(T(t, 3)));
              const double m = w.minCoeff();
              if (m > best_min || (m == best_min && t < best)) {
                best_min = m;
                best = t;
                best_w = w;
              }
            }
          }
      if (best >= 0 && best_min >= -1e-12) break;
      if (best >= 0 && stop_ring == max_ring) stop_ring = r + 1;
    }
    assert(best >= 0);
    if (best_min < -1e-12) ++out.num_outside;
    out.tet[v] = best;
    for (int j = 0; j < 4; ++j) trip.emplace_back(v, T(best, j), best_w[j]);
  }
  out.W.resize(P.rows(), V.rows());
  out.W.setFromTriplets(trip.begin(), trip.end());
  return out;
}

void apply(const BarycentricEmbedding& embedding, const Eigen::Ref<const MatX3d>& coarse_positions,
           Eigen::Ref<MatX3d> dense_out) {
  if (coarse_positions.rows() != embedding.W.cols() || dense_out.rows() != embedding.W.rows())
    throw ParameterError("barycentric apply: size mismatch");
  dense_out.noalias() = embedding.W * coarse_positions;
}

}  // namespace icd::coupling
