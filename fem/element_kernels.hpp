#pragma once
/// Scalar, fully inlined per-element kernels of the explicit force loop: the
/// same laws as constitutive.hpp written on plain 3x3 arrays (row-major,
/// a[3 r + c]) so that the compiler keeps everything in registers. The Eigen
/// versions in constitutive.hpp remain the reference (tangents, stiffness),
/// and the tests compare both through finite differences.
#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>

#if defined(__GNUC__)
#define ICD_FEM_INLINE inline __attribute__((always_inline))
#else
#define ICD_FEM_INLINE inline
#endif

namespace icd::fem::kernels {

/// F = Ds Dm^-1 from the four node positions p0..p3 and Dm^-1 stored column-major (Eigen).
ICD_FEM_INLINE void deformation_gradient(const double* p0, const double* p1, const double* p2,
                                         const double* p3, const double* dinv, double* F) {
  const double d[9] = {p1[0] - p0[0], p2[0] - p0[0], p3[0] - p0[0], p1[1] - p0[1], p2[1] - p0[1],
                       p3[1] - p0[1], p1[2] - p0[2], p2[2] - p0[2], p3[2] - p0[2]};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      F[3 * r + c] =
          d[3 * r] * dinv[3 * c] + d[3 * r + 1] * dinv[1 + 3 * c] + d[3 * r + 2] * dinv[2 + 3 * c];
}

/// H = -V P Dm^-T (row-major), the nodal forces of nodes 1..3 are its columns.
ICD_FEM_INLINE void nodal_forces(const double* P, const double* dinv, double volume, double* H) {
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      H[3 * r + c] =
          -volume * (P[3 * r] * dinv[c] + P[3 * r + 1] * dinv[c + 3] + P[3 * r + 2] * dinv[c + 6]);
}

ICD_FEM_INLINE void linear_stress(const double* F, double mu, double lambda, double* P) {
  const double t = lambda * (F[0] + F[4] + F[8] - 3.0) - 2.0 * mu;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) P[3 * r + c] = mu * (F[3 * r + c] + F[3 * c + r]);
  P[0] += t;
  P[4] += t;
  P[8] += t;
}

ICD_FEM_INLINE void stvk_stress(const double* F, double mu, double lambda, double* P) {
  double E[9];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      E[3 * r + c] = 0.5 * (F[r] * F[c] + F[3 + r] * F[3 + c] + F[6 + r] * F[6 + c]);
  E[0] -= 0.5;
  E[4] -= 0.5;
  E[8] -= 0.5;
  const double t = lambda * (E[0] + E[4] + E[8]);
  double S[9];
  for (int k = 0; k < 9; ++k) S[k] = 2.0 * mu * E[k];
  S[0] += t;
  S[4] += t;
  S[8] += t;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      P[3 * r + c] = F[3 * r] * S[c] + F[3 * r + 1] * S[3 + c] + F[3 * r + 2] * S[6 + c];
}

ICD_FEM_INLINE void stable_neo_hookean_stress(const double* F, double mu, double lambda,
                                              double* P) {
  // Cofactor: columns f1 x f2, f2 x f0, f0 x f1 of F's columns f0, f1, f2.
  const double C[9] = {
      F[4] * F[8] - F[7] * F[5], F[5] * F[6] - F[8] * F[3], F[3] * F[7] - F[6] * F[4],
      F[7] * F[2] - F[1] * F[8], F[8] * F[0] - F[2] * F[6], F[6] * F[1] - F[0] * F[7],
      F[1] * F[5] - F[4] * F[2], F[2] * F[3] - F[5] * F[0], F[0] * F[4] - F[3] * F[1]};
  const double J = F[0] * C[0] + F[3] * C[3] + F[6] * C[6];
  const double s = (lambda + mu) * (J - 1.0) - mu;
  for (int k = 0; k < 9; ++k) P[k] = mu * F[k] + s * C[k];
}

/// Rotation matrix (row-major) of the unit quaternion (w, x, y, z).
ICD_FEM_INLINE void quaternion_matrix(double w, double x, double y, double z, double* R) {
  R[0] = 1 - 2 * (y * y + z * z);
  R[1] = 2 * (x * y - w * z);
  R[2] = 2 * (x * z + w * y);
  R[3] = 2 * (x * y + w * z);
  R[4] = 1 - 2 * (x * x + z * z);
  R[5] = 2 * (y * z - w * x);
  R[6] = 2 * (x * z - w * y);
  R[7] = 2 * (y * z + w * x);
  R[8] = 1 - 2 * (x * x + y * y);
}

/// Scalar version of polar_rotation() (fem/polar.hpp), same iteration and
/// exit rule: q (in/out, warm start) and R (out, row-major) of F.
ICD_FEM_INLINE void polar_rotation(const double* F, Eigen::Quaterniond& q, int max_iterations,
                                   double tolerance, double* R) {
  double qw = q.w(), qx = q.x(), qy = q.y(), qz = q.z();
  bool fresh = false;
  for (int it = 0; it < max_iterations; ++it) {
    quaternion_matrix(qw, qx, qy, qz, R);
    fresh = true;
    double A[9];  // R^T F
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c)
        A[3 * r + c] = R[r] * F[c] + R[3 + r] * F[3 + c] + R[6 + r] * F[6 + c];
    const double a0 = A[7] - A[5], a1 = A[2] - A[6], a2 = A[3] - A[1];
    const double tr = A[0] + A[4] + A[8];
    // N = tr(S) I - S, S = sym(A).
    const double n00 = tr - A[0], n11 = tr - A[4], n22 = tr - A[8];
    const double n01 = -0.5 * (A[1] + A[3]), n02 = -0.5 * (A[2] + A[6]), n12 = -0.5 * (A[5] + A[7]);
    const double c00 = n11 * n22 - n12 * n12, c01 = n02 * n12 - n01 * n22,
                 c02 = n01 * n12 - n02 * n11;
    const double c11 = n00 * n22 - n02 * n02, c12 = n01 * n02 - n00 * n12,
                 c22 = n00 * n11 - n01 * n01;
    const double det = n00 * c00 + n01 * c01 + n02 * c02;
    const double scale = std::abs(tr) + 1e-300;
    double w0, w1, w2;
    if (n00 > 1e-8 * scale && c22 > 1e-8 * scale * scale && det > 1e-8 * scale * scale * scale) {
      const double inv = 1.0 / det;
      w0 = inv * (c00 * a0 + c01 * a1 + c02 * a2);
      w1 = inv * (c01 * a0 + c11 * a1 + c12 * a2);
      w2 = inv * (c02 * a0 + c12 * a1 + c22 * a2);
    } else {
      const double inv = 1.0 / (scale + 1e-9);
      w0 = a0 * inv;
      w1 = a1 * inv;
      w2 = a2 * inv;
    }
    const double angle2 = w0 * w0 + w1 * w1 + w2 * w2;
    if (!(angle2 > tolerance * tolerance)) break;  // also exits on NaN
    // q <- normalize(q * (1, w/2)).
    const double ux = 0.5 * w0, uy = 0.5 * w1, uz = 0.5 * w2;
    const double nw = qw - (qx * ux + qy * uy + qz * uz);
    const double nx = qw * ux + qx + (qy * uz - qz * uy);
    const double ny = qw * uy + qy + (qz * ux - qx * uz);
    const double nz = qw * uz + qz + (qx * uy - qy * ux);
    const double norm = 1.0 / std::sqrt(nw * nw + nx * nx + ny * ny + nz * nz);
    qw = nw * norm;
    qx = nx * norm;
    qy = ny * norm;
    qz = nz * norm;
    fresh = false;
  }
  if (!fresh) quaternion_matrix(qw, qx, qy, qz, R);
  q = Eigen::Quaterniond(qw, qx, qy, qz);
}

/// Corotational: R from the warm-started polar iteration (q in/out); R_out
/// (row-major, optional) receives the rotation used.
ICD_FEM_INLINE void corotational_stress(const double* F, double mu, double lambda,
                                        Eigen::Quaterniond& q, int max_iterations, double tolerance,
                                        double* P, double* R_out = nullptr) {
  double Rl[9];
  double* R = R_out ? R_out : Rl;
  polar_rotation(F, q, max_iterations, tolerance, R);
  double tr = 0;
  for (int k = 0; k < 9; ++k) tr += R[k] * F[k];
  const double t = lambda * (tr - 3.0);
  for (int k = 0; k < 9; ++k) P[k] = 2.0 * mu * (F[k] - R[k]) + t * R[k];
}

/// Bilinear cofactor form: cof(F) = cofactor_bilinear(F, F), and
/// d cof(F)[dF] = cofactor_bilinear(dF, F) + cofactor_bilinear(F, dF) (row-major).
ICD_FEM_INLINE void cofactor_bilinear(const double* A, const double* B, double* C) {
  C[0] = A[4] * B[8] - A[7] * B[5];
  C[1] = A[5] * B[6] - A[8] * B[3];
  C[2] = A[3] * B[7] - A[6] * B[4];
  C[3] = A[7] * B[2] - A[1] * B[8];
  C[4] = A[8] * B[0] - A[2] * B[6];
  C[5] = A[6] * B[1] - A[0] * B[7];
  C[6] = A[1] * B[5] - A[4] * B[2];
  C[7] = A[2] * B[3] - A[5] * B[0];
  C[8] = A[0] * B[4] - A[3] * B[1];
}

/// dP = dP/dF [dF] of linear elasticity: mu (dF + dF^T) + lambda tr(dF) I.
ICD_FEM_INLINE void linear_stress_differential(const double* dF, double mu, double lambda,
                                               double* dP) {
  const double t = lambda * (dF[0] + dF[4] + dF[8]);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) dP[3 * r + c] = mu * (dF[3 * r + c] + dF[3 * c + r]);
  dP[0] += t;
  dP[4] += t;
  dP[8] += t;
}

/// dP of StVK: dF S + F dS, dS = 2 mu dE + lambda tr(dE) I, dE = sym(F^T dF).
ICD_FEM_INLINE void stvk_stress_differential(const double* F, const double* dF, double mu,
                                             double lambda, double* dP) {
  double G[9], dG[9];  // F^T F and F^T dF + dF^T F = 2 dE
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) {
      G[3 * r + c] = F[r] * F[c] + F[3 + r] * F[3 + c] + F[6 + r] * F[6 + c];
      dG[3 * r + c] = F[r] * dF[c] + F[3 + r] * dF[3 + c] + F[6 + r] * dF[6 + c] + dF[r] * F[c] +
                      dF[3 + r] * F[3 + c] + dF[6 + r] * F[6 + c];
    }
  const double trE = 0.5 * (G[0] + G[4] + G[8]) - 1.5;
  const double trdE = 0.5 * (dG[0] + dG[4] + dG[8]);
  double S[9], dS[9];
  for (int k = 0; k < 9; ++k) {
    S[k] = mu * G[k];
    dS[k] = mu * dG[k];
  }
  for (int k = 0; k < 9; k += 4) {
    S[k] += lambda * trE - mu;
    dS[k] += lambda * trdE;
  }
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      dP[3 * r + c] = dF[3 * r] * S[c] + dF[3 * r + 1] * S[3 + c] + dF[3 * r + 2] * S[6 + c] +
                      F[3 * r] * dS[c] + F[3 * r + 1] * dS[3 + c] + F[3 * r + 2] * dS[6 + c];
}

/// dP of stable Neo-Hookean: mu dF + lambda' (cof F : dF) cof F + (lambda' (J - 1) - mu) d cof F
/// [dF].
ICD_FEM_INLINE void stable_neo_hookean_stress_differential(const double* F, const double* dF,
                                                           double mu, double lambda, double* dP) {
  const double lp = lambda + mu;
  double C[9], dC[9], dC2[9];
  cofactor_bilinear(F, F, C);
  cofactor_bilinear(dF, F, dC);
  cofactor_bilinear(F, dF, dC2);
  const double J = F[0] * C[0] + F[3] * C[3] + F[6] * C[6];
  double cdf = 0;
  for (int k = 0; k < 9; ++k) cdf += C[k] * dF[k];
  const double s = lp * (J - 1.0) - mu;
  for (int k = 0; k < 9; ++k) dP[k] = mu * dF[k] + lp * cdf * C[k] + s * (dC[k] + dC2[k]);
}

ICD_FEM_INLINE double determinant(const double* F) {
  return F[0] * (F[4] * F[8] - F[5] * F[7]) - F[1] * (F[3] * F[8] - F[5] * F[6]) +
         F[2] * (F[3] * F[7] - F[4] * F[6]);
}

ICD_FEM_INLINE double linear_energy(const double* F, double mu, double lambda) {
  double sq = 0;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) {
      const double e = 0.5 * (F[3 * r + c] + F[3 * c + r]) - (r == c ? 1.0 : 0.0);
      sq += e * e;
    }
  const double tr = F[0] + F[4] + F[8] - 3.0;
  return mu * sq + 0.5 * lambda * tr * tr;
}

ICD_FEM_INLINE double stvk_energy(const double* F, double mu, double lambda) {
  double E[9];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      E[3 * r + c] =
          0.5 * (F[r] * F[c] + F[3 + r] * F[3 + c] + F[6 + r] * F[6 + c]) - (r == c ? 0.5 : 0.0);
  // E is exactly symmetric (E_rc and E_cr are the same products): |E|^2 as the
  // diagonal plus twice the upper triangle, two short sums instead of a chain
  // of nine dependent additions (the lane kernel's order; its latency was
  // most of the fused health check's cost).
  const double sq =
      (E[0] * E[0] + E[4] * E[4] + E[8] * E[8]) + 2.0 * (E[1] * E[1] + E[2] * E[2] + E[5] * E[5]);
  const double tr = E[0] + E[4] + E[8];
  return mu * sq + 0.5 * lambda * tr * tr;
}

/// Corotational energy density with the rotation R (row-major) of F = R S:
/// mu |S - I|^2 + lambda/2 tr(S - I)^2, S = sym(R^T F).
ICD_FEM_INLINE double corotational_energy(const double* F, const double* R, double mu,
                                          double lambda) {
  double A[9];  // R^T F
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      A[3 * r + c] = R[r] * F[c] + R[3 + r] * F[3 + c] + R[6 + r] * F[6 + c];
  double sq = 0;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) {
      const double e = 0.5 * (A[3 * r + c] + A[3 * c + r]) - (r == c ? 1.0 : 0.0);
      sq += e * e;
    }
  const double tr = A[0] + A[4] + A[8] - 3.0;
  return mu * sq + 0.5 * lambda * tr * tr;
}

ICD_FEM_INLINE double stable_neo_hookean_energy(const double* F, double J, double mu,
                                                double lambda) {
  double ic = 0;
  for (int k = 0; k < 9; ++k) ic += F[k] * F[k];
  return 0.5 * mu * (ic - 3.0) - mu * (J - 1.0) + 0.5 * (lambda + mu) * (J - 1.0) * (J - 1.0);
}

}  // namespace icd::fem::kernels
