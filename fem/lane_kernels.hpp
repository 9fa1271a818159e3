#pragma once
/// Force kernels that evaluate kLanes = 8 elements at a time in
/// structure-of-arrays lane loops (a[k][lane]) that the compiler vectorises.
/// Per element, the arithmetic is the same sequence of operations as the
/// scalar kernels (element_kernels.hpp), so results are bitwise identical.
#include "fem/material.hpp"

namespace icd::fem::lanes {

constexpr int kLanes = 8;

/// Per block of 8 elements: Dm^-1 (9 x 8, row-major entries k = 3 r + c) and volumes (8).
struct Block {
  double dinv[9][kLanes];
  double volume[kLanes];
};

/// Forces of the elements of one block. x: positions (#V x 3 row-major);
/// tets: the block's first tet (4 indices each); count <= 8 valid lanes.
/// Writes out[e][12] (nodal forces of node 0..3) for the valid lanes.
template <MaterialModel kModel>
inline void block_forces(const double* x, const int* tets, int count, const Block& b, double mu, double lambda,
                         double (*out)[12]) {
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
          E[3 * r + c] = 0.5 * (F[r][l] * F[c][l] + F[3 + r][l] * F[3 + c][l] + F[6 + r][l] * F[6 + c][l]);
      E[0] -= 0.5;
      E[4] -= 0.5;
      E[8] -= 0.5;
      const double t = lambda * (E[0] + E[4] + E[8]);
      for (int k = 0; k < 9; ++k) S[k][l] = 2.0 * mu * E[k];
      S[0][l] += t;
      S[4][l] += t;
      S[8][l] += t;
    }
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c)
        for (int l = 0; l < kLanes; ++l)
          P[3 * r + c][l] = F[3 * r][l] * S[c][l] + F[3 * r + 1][l] * S[3 + c][l] + F[3 * r + 2][l] * S[6 + c][l];
  } else {
    static_assert(kModel == MaterialModel::StableNeoHookean, "no lane kernel for this model");
    for (int l = 0; l < kLanes; ++l) {
      const double C0 = F[4][l] * F[8][l] - F[7][l] * F[5][l], C1 = F[5][l] * F[6][l] - F[8][l] * F[3][l],
                   C2 = F[3][l] * F[7][l] - F[6][l] * F[4][l], C3 = F[7][l] * F[2][l] - F[1][l] * F[8][l],
                   C4 = F[8][l] * F[0][l] - F[2][l] * F[6][l], C5 = F[6][l] * F[1][l] - F[0][l] * F[7][l],
                   C6 = F[1][l] * F[5][l] - F[4][l] * F[2][l], C7 = F[2][l] * F[3][l] - F[5][l] * F[0][l],
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
  // H = -V P Dm^-T; nodes 1..3 are its columns, node 0 minus their sum.
  double H[9][kLanes];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      for (int l = 0; l < kLanes; ++l)
        H[3 * r + c][l] = -b.volume[l] * (P[3 * r][l] * b.dinv[c][l] + P[3 * r + 1][l] * b.dinv[c + 3][l] +
                                          P[3 * r + 2][l] * b.dinv[c + 6][l]);
  for (int l = 0; l < count; ++l)
    for (int r = 0; r < 3; ++r) {
      out[l][3 + r] = H[3 * r][l];
      out[l][6 + r] = H[3 * r + 1][l];
      out[l][9 + r] = H[3 * r + 2][l];
      out[l][r] = -(H[3 * r][l] + H[3 * r + 1][l] + H[3 * r + 2][l]);
    }
}

}  // namespace icd::fem::lanes
