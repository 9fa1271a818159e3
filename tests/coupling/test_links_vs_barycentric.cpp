#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include <Eigen/Dense>

#include <icd/coupling/barycentric_embedding.hpp>
#include <icd/coupling/rigid_links.hpp>
#include <icd/mesh/core/primitives.hpp>

namespace icd::coupling {
namespace {

// Dense points on the boundary of a structured coarse box, slightly outside
// it (like a dense surface around its coarse model).
MatX3d dense_points_around(const TetMesh& box, double offset) {
  MatX3d P(box.F.rows(), 3);
  for (int f = 0; f < box.F.rows(); ++f) {
    const Eigen::RowVector3d a = box.V.row(box.F(f, 0)), b = box.V.row(box.F(f, 1)),
                             c = box.V.row(box.F(f, 2));
    const Eigen::RowVector3d n = (b - a).cross(c - a).normalized();
    P.row(f) = (a + b + c) / 3.0 + offset * n;
  }
  return P;
}

// At rest and under rigid motions the two mappings agree exactly (both are
// exact there). Under a smooth bending of curvature kappa the barycentric
// embedding is a linear interpolation: error O(kappa h^2), 4x smaller when
// the cell h halves. A rigid link keeps its length (paper 3.1), so it cannot
// follow the stretch of the bent surface layer: its error is O(h * strain),
// strain ~ kappa t at distance t = 0.125 from the neutral axis: first order,
// about 2x smaller when h halves. The test asserts both rates and reports the
// numbers.
TEST(LinksVsBarycentric, ExactWhenRigidAndConvergentUnderBending) {
  double prev_links = 0, prev_bary = 0;
  const double t = 0.125;  // half thickness: largest distance from the neutral axis
  for (int refine : {1, 2}) {
    BoxMeshOptions o;
    o.size = {1.0, 0.25, 0.25};
    o.nx = 8 * refine;
    o.ny = o.nz = 2 * refine;
    const TetMesh box = make_box_tet_mesh(o);
    const double h = 1.0 / o.nx;
    const MatX3d P = dense_points_around(box, 0.2 * h);
    const RigidLinks links = build_rigid_links(P, box.V, boundary_nodes(box.F));
    const BarycentricEmbedding emb = build_barycentric_embedding(P, box.V, box.T);
    MatX3d by_links(P.rows(), 3), by_bary(P.rows(), 3);

    apply(links, box.V, by_links);
    apply(emb, box.V, by_bary);
    EXPECT_LT((by_links - P).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LT((by_bary - P).cwiseAbs().maxCoeff(), 1e-12);

    const Eigen::Matrix3d R =
        Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    const MatX3d Vr = (box.V * R.transpose()).rowwise() + Eigen::RowVector3d(0.3, -1, 2);
    const MatX3d Pr = (P * R.transpose()).rowwise() + Eigen::RowVector3d(0.3, -1, 2);
    apply(links, Vr, by_links);
    apply(emb, Vr, by_bary);
    EXPECT_LT((by_links - Pr).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LT((by_bary - Pr).cwiseAbs().maxCoeff(), 1e-12);

    // Bending about y with curvature kappa: (x, y, z) -> arc of radius 1/kappa.
    const double kappa = 0.5;
    auto bend = [&](const MatX3d& X) {
      MatX3d Y(X.rows(), 3);
      for (int i = 0; i < X.rows(); ++i) {
        const double r = 1.0 / kappa - X(i, 2), angle = kappa * X(i, 0);
        Y.row(i) << r * std::sin(angle), X(i, 1), 1.0 / kappa - r * std::cos(angle);
      }
      return Y;
    };
    const MatX3d Vb = bend(box.V), Pb = bend(P);
    apply(links, Vb, by_links);
    apply(emb, Vb, by_bary);
    const double diff = (by_links - by_bary).rowwise().norm().maxCoeff();
    const double err_links = (by_links - Pb).rowwise().norm().maxCoeff();
    const double err_bary = (by_bary - Pb).rowwise().norm().maxCoeff();
    std::printf(
        "h = %.4f: |links - barycentric| max %.3e, links error %.3e, barycentric error %.3e "
        "(kappa h^2 = %.3e)\n",
        h, diff, err_links, err_bary, kappa * h * h);
    EXPECT_LT(err_bary, kappa * h * h);
    EXPECT_LT(err_links, kappa * h * t);
    EXPECT_LT(diff, err_links + err_bary);
    if (refine == 2) {
      EXPECT_LT(err_bary, 0.35 * prev_bary);   // second order
      EXPECT_LT(err_links, 0.7 * prev_links);  // first order
      EXPECT_GT(err_links, 0.35 * prev_links);
    }
    prev_links = err_links;
    prev_bary = err_bary;
  }
}

}  // namespace
}  // namespace icd::coupling
