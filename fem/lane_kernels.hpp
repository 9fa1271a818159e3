#pragma once
/// Force kernels that evaluate kLanes = 8 elements at a time in
/// structure-of-arrays lane loops (a[k][lane]) that the compiler vectorises.
/// Per element, the arithmetic is the same sequence of operations as the
/// scalar kernels (element_kernels.hpp), so results are bitwise identical.
/// Always inlined: lane_loops.cpp compiles the loops that call them for two
/// instruction sets.
#include <icd/fem/element_kernels.hpp>
#include <icd/fem/material.hpp>

namespace icd::fem::lanes {

constexpr int kLanes = 8;

/// Per block of 8 elements: Dm^-1 (9 x 8, row-major entries k = 3 r + c) and volumes (8).
struct Block {
  double dinv[9][kLanes];
  double volume[kLanes];
};

/// What a block's force evaluation also computes for a health check.
enum class LaneCheck {
  None,
  Full,        ///< energy density psi and det F of every lane
  Orientation  ///< det F of every lane only (inversion and NaN test)
};

/// Nodal forces from the first Piola-Kirchhoff stress (or its differential)
/// of the lanes of one block: H = -V P Dm^-T, nodes 1..3 are its columns,
/// node 0 minus their sum; out[e][12] for the `count` valid lanes.
[[gnu::always_inline]] inline void scatter_nodal(const double (*P)[kLanes], const Block& b,
                                                 int count, double (*out)[12]) {
  double H[9][kLanes];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      for (int l = 0; l < kLanes; ++l)
        H[3 * r + c][l] =
            -b.volume[l] * (P[3 * r][l] * b.dinv[c][l] + P[3 * r + 1][l] * b.dinv[c + 3][l] +
                            P[3 * r + 2][l] * b.dinv[c + 6][l]);
  for (int l = 0; l < count; ++l)
    for (int r = 0; r < 3; ++r) {
      out[l][3 + r] = H[3 * r][l];
      out[l][6 + r] = H[3 * r + 1][l];
      out[l][9 + r] = H[3 * r + 2][l];
      out[l][r] = -(H[3 * r][l] + H[3 * r + 1][l] + H[3 * r + 2][l]);
    }
}

/// Forces of the elements of one block. x: positions (#V x 3 row-major);
/// tets: the block's first tet (4 indices each); count <= 8 valid lanes.
/// Writes out[e][12] (nodal forces of node 0..3) for the valid lanes.
/// kCheck Full: also writes the energy density psi[l] (J/m^3) and det F det[l]
/// of every lane, with the same operations as kernels::*_energy and
/// kernels::determinant (bitwise equal to ElasticForces::health());
/// Orientation: det[l] only (psi untouched, may be null).
template <MaterialModel kModel, LaneCheck kCheck = LaneCheck::None>
[[gnu::always_inline]] inline void block_forces(const double* x, const int* tets, int count,
                                                const Block& b, double mu, double lambda,
                                                double (*out)[12], double* psi = nullptr,
                                                double* det = nullptr) {
  double d[9][kLanes];
  for (int l = 0; l < kLanes; ++l) {
    if (l < count) {
      const int* t = tets + 4 * l;
      const double* p0 = x + 3 * t[0];
      for (int c = 0; c < 3; ++c) {
        const double* p = x + 3 * t[c + 1];
        d[c][l] = p[0] - p0[0];
        d[3 + c][l] = p[1] - p0[1];
        d[6 + c][l] = p[2] - p0[2];
      }
    } else {
      for (int k = 0; k < 9; ++k) d[k][l] = 0.0;
    }
  }
  // b.dinv holds Dm^-1 column-major like the scalar kernel: entry (k, c) at [k + 3 c].
  double F[9][kLanes];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      for (int l = 0; l < kLanes; ++l)
        F[3 * r + c][l] = d[3 * r][l] * b.dinv[3 * c][l] + d[3 * r + 1][l] * b.dinv[1 + 3 * c][l] +
                          d[3 * r + 2][l] * b.dinv[2 + 3 * c][l];
  constexpr bool kHealth = kCheck == LaneCheck::Full;
  if constexpr (kCheck != LaneCheck::None) {
    // det F: here for linear and stable Neo-Hookean; StVK computes
    // it in its strain loop below, where F is already in registers (measured
    // ~2.5 ns/tet cheaper with AVX2 than this separate pass).
    if constexpr (kModel != MaterialModel::StVK)
      for (int l = 0; l < kLanes; ++l)
        det[l] = F[0][l] * (F[4][l] * F[8][l] - F[5][l] * F[7][l]) -
                 F[1][l] * (F[3][l] * F[8][l] - F[5][l] * F[6][l]) +
                 F[2][l] * (F[3][l] * F[7][l] - F[4][l] * F[6][l]);
    if constexpr (kModel == MaterialModel::Linear && kHealth) {
      for (int l = 0; l < kLanes; ++l) {
        double sq = 0;
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 3; ++c) {
            const double e = 0.5 * (F[3 * r + c][l] + F[3 * c + r][l]) - (r == c ? 1.0 : 0.0);
            sq += e * e;
          }
        const double tr = F[0][l] + F[4][l] + F[8][l] - 3.0;
        psi[l] = mu * sq + 0.5 * lambda * tr * tr;
      }
    } else if constexpr (kModel == MaterialModel::StableNeoHookean && kHealth) {
      for (int l = 0; l < kLanes; ++l) {
        double ic = 0;
        for (int k = 0; k < 9; ++k) ic += F[k][l] * F[k][l];
        const double J = det[l];
        psi[l] =
            0.5 * mu * (ic - 3.0) - mu * (J - 1.0) + 0.5 * (lambda + mu) * (J - 1.0) * (J - 1.0);
      }
    }  // StVK: from E below
  }
  double P[9][kLanes];
  if constexpr (kModel == MaterialModel::Linear) {
    for (int l = 0; l < kLanes; ++l) {
      const double t = lambda * (F[0][l] + F[4][l] + F[8][l] - 3.0) - 2.0 * mu;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) P[3 * r + c][l] = mu * (F[3 * r + c][l] + F[3 * c + r][l]);
      P[0][l] += t;
      P[4][l] += t;
      P[8][l] += t;
    }
  } else if constexpr (kModel == MaterialModel::StVK) {
    double S[9][kLanes];
    for (int l = 0; l < kLanes; ++l) {
      double E[9];
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
          E[3 * r + c] =
              0.5 * (F[r][l] * F[c][l] + F[3 + r][l] * F[3 + c][l] + F[6 + r][l] * F[6 + c][l]);
      E[0] -= 0.5;
      E[4] -= 0.5;
      E[8] -= 0.5;
      if constexpr (kHealth) {
        // kernels::stvk_energy's operations: E is exactly symmetric, |E|^2 =
        // diagonal + 2 x upper triangle (measured ~2 ns/tet cheaper with AVX2
        // than the sequential sum over all nine entries).
        const double sq = (E[0] * E[0] + E[4] * E[4] + E[8] * E[8]) +
                          2.0 * (E[1] * E[1] + E[2] * E[2] + E[5] * E[5]);
        const double tr = E[0] + E[4] + E[8];
        psi[l] = mu * sq + 0.5 * lambda * tr * tr;
      }
      if constexpr (kCheck != LaneCheck::None) {
        det[l] = F[0][l] * (F[4][l] * F[8][l] - F[5][l] * F[7][l]) -
                 F[1][l] * (F[3][l] * F[8][l] - F[5][l] * F[6][l]) +
                 F[2][l] * (F[3][l] * F[7][l] - F[4][l] * F[6][l]);
      }
      const double t = lambda * (E[0] + E[4] + E[8]);
      for (int k = 0; k < 9; ++k) S[k][l] = 2.0 * mu * E[k];
      S[0][l] += t;
      S[4][l] += t;
      S[8][l] += t;
    }
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c)
        for (int l = 0; l < kLanes; ++l)
          P[3 * r + c][l] =
              F[3 * r][l] * S[c][l] + F[3 * r + 1][l] * S[3 + c][l] + F[3 * r + 2][l] * S[6 + c][l];
  } else {
    static_assert(kModel == MaterialModel::StableNeoHookean, "no lane kernel for this model");
    for (int l = 0; l < kLanes; ++l) {
      const double C0 = F[4][l] * F[8][l] - F[7][l] * F[5][l],
                   C1 = F[5][l] * F[6][l] - F[8][l] * F[3][l],
                   C2 = F[3][l] * F[7][l] - F[6][l] * F[4][l],
                   C3 = F[7][l] * F[2][l] - F[1][l] * F[8][l],
                   C4 = F[8][l] * F[0][l] - F[2][l] * F[6][l],
                   C5 = F[6][l] * F[1][l] - F[0][l] * F[7][l],
                   C6 = F[1][l] * F[5][l] - F[4][l] * F[2][l],
                   C7 = F[2][l] * F[3][l] - F[5][l] * F[0][l],
                   C8 = F[0][l] * F[4][l] - F[3][l] * F[1][l];
      const double J = F[0][l] * C0 + F[3][l] * C3 + F[6][l] * C6;
      const double s = (lambda + mu) * (J - 1.0) - mu;
      P[0][l] = mu * F[0][l] + s * C0;
      P[1][l] = mu * F[1][l] + s * C1;
      P[2][l] = mu * F[2][l] + s * C2;
      P[3][l] = mu * F[3][l] + s * C3;
      P[4][l] = mu * F[4][l] + s * C4;
      P[5][l] = mu * F[5][l] + s * C5;
      P[6][l] = mu * F[6][l] + s * C6;
      P[7][l] = mu * F[7][l] + s * C7;
      P[8][l] = mu * F[8][l] + s * C8;
    }
  }
  scatter_nodal(P, b, count, out);
}

/// Force differentials df = -K(x) dx of the elements of one block (the
/// directional derivative of block_forces along dx), same layout as
/// block_forces: out[e][12] for the valid lanes. Linear, StVK and stable
/// Neo-Hookean (the laws of element_kernels.hpp, *_stress_differential).
template <MaterialModel kModel>
[[gnu::always_inline]] inline void block_differential(const double* x, const double* dx,
                                                      const int* tets, int count, const Block& b,
                                                      double mu, double lambda, double (*out)[12]) {
  double d[9][kLanes], dd[9][kLanes];
  for (int l = 0; l < kLanes; ++l) {
    if (l < count) {
      const int* t = tets + 4 * l;
      const double* p0 = x + 3 * t[0];
      const double* q0 = dx + 3 * t[0];
      for (int c = 0; c < 3; ++c) {
        const double* p = x + 3 * t[c + 1];
        const double* q = dx + 3 * t[c + 1];
        for (int r = 0; r < 3; ++r) {
          d[3 * r + c][l] = p[r] - p0[r];
          dd[3 * r + c][l] = q[r] - q0[r];
        }
      }
    } else {
      for (int k = 0; k < 9; ++k) d[k][l] = dd[k][l] = 0.0;
    }
  }
  double F[9][kLanes], dF[9][kLanes];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      for (int l = 0; l < kLanes; ++l) {
        F[3 * r + c][l] = d[3 * r][l] * b.dinv[3 * c][l] + d[3 * r + 1][l] * b.dinv[1 + 3 * c][l] +
                          d[3 * r + 2][l] * b.dinv[2 + 3 * c][l];
        dF[3 * r + c][l] = dd[3 * r][l] * b.dinv[3 * c][l] +
                           dd[3 * r + 1][l] * b.dinv[1 + 3 * c][l] +
                           dd[3 * r + 2][l] * b.dinv[2 + 3 * c][l];
      }
  double dP[9][kLanes];
  if constexpr (kModel == MaterialModel::Linear) {
    for (int l = 0; l < kLanes; ++l) {
      const double t = lambda * (dF[0][l] + dF[4][l] + dF[8][l]);
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) dP[3 * r + c][l] = mu * (dF[3 * r + c][l] + dF[3 * c + r][l]);
      dP[0][l] += t;
      dP[4][l] += t;
      dP[8][l] += t;
    }
  } else if constexpr (kModel == MaterialModel::StVK) {
    double S[9][kLanes], dS[9][kLanes];  // first F^T F and F^T dF + dF^T F
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c)
        for (int l = 0; l < kLanes; ++l) {
          S[3 * r + c][l] =
              F[r][l] * F[c][l] + F[3 + r][l] * F[3 + c][l] + F[6 + r][l] * F[6 + c][l];
          dS[3 * r + c][l] = F[r][l] * dF[c][l] + F[3 + r][l] * dF[3 + c][l] +
                             F[6 + r][l] * dF[6 + c][l] + dF[r][l] * F[c][l] +
                             dF[3 + r][l] * F[3 + c][l] + dF[6 + r][l] * F[6 + c][l];
        }
    // S = mu (F^T F - I) + lambda tr(E) I, dS = mu (F^T dF + dF^T F) + lambda tr(dE) I.
    for (int l = 0; l < kLanes; ++l) {
      const double trE = 0.5 * (S[0][l] + S[4][l] + S[8][l]) - 1.5;
      const double trdE = 0.5 * (dS[0][l] + dS[4][l] + dS[8][l]);
      for (int k = 0; k < 9; ++k) {
        S[k][l] *= mu;
        dS[k][l] *= mu;
      }
      for (int k = 0; k < 9; k += 4) {
        S[k][l] += lambda * trE - mu;
        dS[k][l] += lambda * trdE;
      }
    }
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c)
        for (int l = 0; l < kLanes; ++l)
          dP[3 * r + c][l] = dF[3 * r][l] * S[c][l] + dF[3 * r + 1][l] * S[3 + c][l] +
                             dF[3 * r + 2][l] * S[6 + c][l] + F[3 * r][l] * dS[c][l] +
                             F[3 * r + 1][l] * dS[3 + c][l] + F[3 * r + 2][l] * dS[6 + c][l];
  } else {
    static_assert(kModel == MaterialModel::StableNeoHookean, "no lane differential for this model");
    const double lp = lambda + mu;
    for (int l = 0; l < kLanes; ++l) {
      double f[9], g[9], C[9], dC[9], dC2[9];
      for (int k = 0; k < 9; ++k) {
        f[k] = F[k][l];
        g[k] = dF[k][l];
      }
      kernels::cofactor_bilinear(f, f, C);
      kernels::cofactor_bilinear(g, f, dC);
      kernels::cofactor_bilinear(f, g, dC2);
      const double J = f[0] * C[0] + f[3] * C[3] + f[6] * C[6];
      double cdf = 0;
      for (int k = 0; k < 9; ++k) cdf += C[k] * g[k];
      const double s = lp * (J - 1.0) - mu;
      for (int k = 0; k < 9; ++k) dP[k][l] = mu * g[k] + lp * cdf * C[k] + s * (dC[k] + dC2[k]);
    }
  }
  scatter_nodal(dP, b, count, out);
}

}  // namespace icd::fem::lanes
