#pragma once
/// Constitutive laws on the deformation gradient F of a linear tetrahedron:
/// energy density psi(F) (J/m^3), first Piola-Kirchhoff stress P = dpsi/dF (Pa)
/// and its directional derivative dP = d2psi/dF2 : dF. Header-only so that the
/// element loops inline them.
#include <Eigen/Core>
#include <Eigen/LU>

#include <icd/fem/material.hpp>

namespace icd::fem {

/// Cofactor matrix dJ/dF of a 3x3 F (columns f0, f1, f2): [f1 x f2, f2 x f0, f0 x f1].
inline Eigen::Matrix3d cofactor(const Eigen::Matrix3d& F) {
  Eigen::Matrix3d C;
  C.col(0) = F.col(1).cross(F.col(2));
  C.col(1) = F.col(2).cross(F.col(0));
  C.col(2) = F.col(0).cross(F.col(1));
  return C;
}

/// Linear elasticity: eps = sym(F) - I, psi = mu eps:eps + lambda/2 tr(eps)^2.
struct LinearLaw {
  double mu, lambda;
  double energy(const Eigen::Matrix3d& F) const {
    const Eigen::Matrix3d eps = 0.5 * (F + F.transpose()) - Eigen::Matrix3d::Identity();
    const double tr = eps.trace();
    return mu * eps.squaredNorm() + 0.5 * lambda * tr * tr;
  }
  Eigen::Matrix3d stress(const Eigen::Matrix3d& F) const {
    Eigen::Matrix3d P = mu * (F + F.transpose());
    P.diagonal().array() += lambda * (F.trace() - 3.0) - 2.0 * mu;
    return P;
  }
  Eigen::Matrix3d stress_differential(const Eigen::Matrix3d& /*F*/,
                                      const Eigen::Matrix3d& dF) const {
    Eigen::Matrix3d dP = mu * (dF + dF.transpose());
    dP.diagonal().array() += lambda * dF.trace();
    return dP;
  }
};

/// St. Venant-Kirchhoff (paper section 3, O'Brien & Hodgins): Green strain
/// E = (F^T F - I)/2, psi = mu E:E + lambda/2 tr(E)^2, P = F (2 mu E + lambda tr(E) I).
struct StVKLaw {
  double mu, lambda;
  double energy(const Eigen::Matrix3d& F) const {
    Eigen::Matrix3d E = 0.5 * (F.transpose() * F);
    E.diagonal().array() -= 0.5;
    const double tr = E.trace();
    return mu * E.squaredNorm() + 0.5 * lambda * tr * tr;
  }
  Eigen::Matrix3d second_pk(const Eigen::Matrix3d& F) const {
    Eigen::Matrix3d E = 0.5 * (F.transpose() * F);
    E.diagonal().array() -= 0.5;
    Eigen::Matrix3d S = 2.0 * mu * E;
    S.diagonal().array() += lambda * E.trace();
    return S;
  }
  Eigen::Matrix3d stress(const Eigen::Matrix3d& F) const { return F * second_pk(F); }
  Eigen::Matrix3d stress_differential(const Eigen::Matrix3d& F, const Eigen::Matrix3d& dF) const {
    const Eigen::Matrix3d FtdF = F.transpose() * dF;
    const Eigen::Matrix3d dE = 0.5 * (FtdF + FtdF.transpose());
    Eigen::Matrix3d dS = 2.0 * mu * dE;
    dS.diagonal().array() += lambda * dE.trace();
    return dF * second_pk(F) + F * dS;
  }
};

/// Stable Neo-Hookean in the Kim-Eberle form (Smith et al. 2018):
/// psi = mu/2 (I_C - 3) - mu (J - 1) + lambda'/2 (J - 1)^2 with lambda' = lambda + mu,
/// so that its linearisation at F = I is linear elasticity with (mu, lambda).
/// Defined and smooth for J <= 0 (inversion-safe); the rest state is stress-free.
struct StableNeoHookeanLaw {
  double mu, lambda;
  double energy(const Eigen::Matrix3d& F) const {
    const double lp = lambda + mu;
    const double J = F.determinant();
    return 0.5 * mu * (F.squaredNorm() - 3.0) - mu * (J - 1.0) + 0.5 * lp * (J - 1.0) * (J - 1.0);
  }
  Eigen::Matrix3d stress(const Eigen::Matrix3d& F) const {
    const double lp = lambda + mu;
    const Eigen::Matrix3d C = cofactor(F);
    const double J = F.col(0).dot(C.col(0));
    return mu * F + (lp * (J - 1.0) - mu) * C;
  }
  Eigen::Matrix3d stress_differential(const Eigen::Matrix3d& F, const Eigen::Matrix3d& dF) const {
    const double lp = lambda + mu;
    const Eigen::Matrix3d C = cofactor(F);
    const double J = F.col(0).dot(C.col(0));
    Eigen::Matrix3d dC;
    dC.col(0) = dF.col(1).cross(F.col(2)) + F.col(1).cross(dF.col(2));
    dC.col(1) = dF.col(2).cross(F.col(0)) + F.col(2).cross(dF.col(0));
    dC.col(2) = dF.col(0).cross(F.col(1)) + F.col(0).cross(dF.col(1));
    return mu * dF + lp * C.cwiseProduct(dF).sum() * C + (lp * (J - 1.0) - mu) * dC;
  }
};

/// Corotational linear elasticity with the rotation R of F = R S given
/// (see polar_rotation): psi = mu |S - I|^2 + lambda/2 tr(S - I)^2,
/// P = 2 mu (F - R) + lambda tr(S - I) R. The differential includes dR
/// (exact tangent): dR = R [w]_x, (tr(S) I - S) w = 2 axial(skew(R^T dF)).
struct CorotationalLaw {
  double mu, lambda;
  double energy(const Eigen::Matrix3d& F, const Eigen::Matrix3d& R) const {
    Eigen::Matrix3d S = R.transpose() * F;
    S = 0.5 * (S + S.transpose());
    S.diagonal().array() -= 1.0;
    const double tr = S.trace();
    return mu * S.squaredNorm() + 0.5 * lambda * tr * tr;
  }
  Eigen::Matrix3d stress(const Eigen::Matrix3d& F, const Eigen::Matrix3d& R) const {
    const double trS = R.cwiseProduct(F).sum();  // tr(R^T F)
    return 2.0 * mu * (F - R) + lambda * (trS - 3.0) * R;
  }
  Eigen::Matrix3d stress_differential(const Eigen::Matrix3d& F, const Eigen::Matrix3d& R,
                                      const Eigen::Matrix3d& dF) const {
    const Eigen::Matrix3d A = R.transpose() * F;
    Eigen::Matrix3d N = -0.5 * (A + A.transpose());
    const double trS = A.trace();
    N.diagonal().array() += trS;
    const Eigen::Matrix3d RtdF = R.transpose() * dF;
    const Eigen::Vector3d a(RtdF(2, 1) - RtdF(1, 2), RtdF(0, 2) - RtdF(2, 0),
                            RtdF(1, 0) - RtdF(0, 1));
    const Eigen::Vector3d w = N.inverse() * a;
    Eigen::Matrix3d W;
    W << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
    const Eigen::Matrix3d dR = R * W;
    return 2.0 * mu * (dF - dR) + lambda * RtdF.trace() * R + lambda * (trS - 3.0) * dR;
  }
};

}  // namespace icd::fem
