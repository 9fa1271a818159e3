#include <icd/fem/strain_rate_damping.hpp>

#include <cmath>
#include <string>

#include <icd/fem/element_kernels.hpp>
#include <icd/mesh/core/error.hpp>

namespace icd::fem {
namespace {

// F, Fdot (row-major) of element e.
inline void rates(const TetMeshData& mesh, const Eigen::Ref<const MatX3d>& x,
                  const Eigen::Ref<const MatX3d>& v, int e, double* F, double* Fdot) {
  const int* t = mesh.tets.data() + 4 * e;
  const double* D = mesh.dm_inv[e].data();
  double p[4][3], q[4][3];
  for (int a = 0; a < 4; ++a)
    for (int c = 0; c < 3; ++c) {
      p[a][c] = x(t[a], c);
      q[a][c] = v(t[a], c);
    }
  kernels::deformation_gradient(p[0], p[1], p[2], p[3], D, F);
  kernels::deformation_gradient(q[0], q[1], q[2], q[3], D, Fdot);
}

// Edot = sym(F^T Fdot) (row-major).
inline void strain_rate(const double* F, const double* Fdot, double* Edot) {
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      Edot[3 * r + c] = 0.5 * (F[r] * Fdot[c] + F[3 + r] * Fdot[3 + c] + F[6 + r] * Fdot[6 + c] +
                               Fdot[r] * F[c] + Fdot[3 + r] * F[3 + c] + Fdot[6 + r] * F[6 + c]);
}

// Nodal damping forces out[12] (nodes 0..3) of one element with F, Fdot,
// Dm^-1 (column-major) and rest volume.
inline void element_forces(const StrainRateDamping& damping, const double* F, const double* Fdot,
                           const double* dinv, double volume, double* out) {
  double Edot[9], S[9], P[9], H[9];
  strain_rate(F, Fdot, Edot);
  const double t = damping.phi * (Edot[0] + Edot[4] + Edot[8]);
  for (int k = 0; k < 9; ++k) S[k] = 2.0 * damping.psi * Edot[k];
  S[0] += t;
  S[4] += t;
  S[8] += t;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      P[3 * r + c] = F[3 * r] * S[c] + F[3 * r + 1] * S[3 + c] + F[3 * r + 2] * S[6 + c];
  kernels::nodal_forces(P, dinv, volume, H);
  for (int r = 0; r < 3; ++r) {
    out[3 + r] = H[3 * r];
    out[6 + r] = H[3 * r + 1];
    out[9 + r] = H[3 * r + 2];
    out[r] = -(H[3 * r] + H[3 * r + 1] + H[3 * r + 2]);
  }
}

}  // namespace

void validate(const StrainRateDamping& damping) {
  auto bad = [](const char* field, double value) {
    throw ParameterError(std::string("fem::StrainRateDamping.") + field + " = " +
                         std::to_string(value) +
                         " is invalid: expected a finite value >= 0 (Pa s)");
  };
  if (!(damping.phi >= 0) || !std::isfinite(damping.phi)) bad("phi", damping.phi);
  if (!(damping.psi >= 0) || !std::isfinite(damping.psi)) bad("psi", damping.psi);
}

void add_strain_rate_damping_forces(const TetMeshData& mesh, const StrainRateDamping& damping,
                                    const Eigen::Ref<const MatX3d>& x,
                                    const Eigen::Ref<const MatX3d>& v, Eigen::Ref<MatX3d> f) {
  if (x.rows() != mesh.num_nodes || v.rows() != mesh.num_nodes || f.rows() != mesh.num_nodes)
    throw ParameterError("fem::add_strain_rate_damping_forces: x, v and f must have #V = " +
                         std::to_string(mesh.num_nodes) + " rows");
  if (!damping.enabled()) return;
  for (int e = 0; e < mesh.num_tets(); ++e) {
    double F[9], Fdot[9], out[12];
    rates(mesh, x, v, e, F, Fdot);
    element_forces(damping, F, Fdot, mesh.dm_inv[e].data(), mesh.rest_volume[e], out);
    const int* t = mesh.tets.data() + 4 * e;
    for (int a = 0; a < 4; ++a)
      for (int r = 0; r < 3; ++r) f(t[a], r) += out[3 * a + r];
  }
}

void add_strain_rate_damping_matrix(const TetMeshData& mesh, const StiffnessPattern& pattern,
                                    const StrainRateDamping& damping,
                                    const Eigen::Ref<const MatX3d>& x, double scale,
                                    Eigen::SparseMatrix<double>& A) {
  if (x.rows() != mesh.num_nodes || A.rows() != 3 * mesh.num_nodes || A.cols() != A.rows())
    throw ParameterError("fem::add_strain_rate_damping_matrix: expected x with #V = " +
                         std::to_string(mesh.num_nodes) + " rows and a 3#V x 3#V matrix");
  if (!damping.enabled()) return;
  double* val = A.valuePtr();
  const MatX3d zero = MatX3d::Zero(mesh.num_nodes, 3);
  for (int e = 0; e < mesh.num_tets(); ++e) {
    const int* t = mesh.tets.data() + 4 * e;
    double F[9], unused[9];
    rates(mesh, x, zero, e, F, unused);
    const Eigen::Matrix<double, 4, 3> G = mesh.shape_gradients(e);
    for (int b = 0; b < 4; ++b)
      for (int c = 0; c < 3; ++c) {
        double Fdot[9] = {0, 0, 0, 0, 0,
                          0, 0, 0, 0};  // unit velocity of dof (b, c): row c of Fdot is grad N_b
        for (int k = 0; k < 3; ++k) Fdot[3 * c + k] = G(b, k);
        double col[12];
        element_forces(damping, F, Fdot, mesh.dm_inv[e].data(), mesh.rest_volume[e], col);
        for (int a = 0; a < 4; ++a) {
          double* block = val + pattern.block_offset(e, a, b) + c * pattern.column_length(t[b]);
          block[0] -= scale * col[3 * a];  // D = -df_d/dv
          block[1] -= scale * col[3 * a + 1];
          block[2] -= scale * col[3 * a + 2];
        }
      }
  }
}

double strain_rate_dissipation(const TetMeshData& mesh, const StrainRateDamping& damping,
                               const Eigen::Ref<const MatX3d>& x,
                               const Eigen::Ref<const MatX3d>& v) {
  if (x.rows() != mesh.num_nodes || v.rows() != mesh.num_nodes)
    throw ParameterError("fem::strain_rate_dissipation: x and v must have #V = " +
                         std::to_string(mesh.num_nodes) + " rows");
  double R = 0;
  for (int e = 0; e < mesh.num_tets(); ++e) {
    double F[9], Fdot[9], Edot[9];
    rates(mesh, x, v, e, F, Fdot);
    strain_rate(F, Fdot, Edot);
    double sq = 0;
    for (double d : Edot) sq += d * d;
    const double tr = Edot[0] + Edot[4] + Edot[8];
    R += 0.5 * mesh.rest_volume[e] * (2.0 * damping.psi * sq + damping.phi * tr * tr);
  }
  return R;
}

}  // namespace icd::fem
