#pragma once
/// Viscous damping on the rate of Green strain (O'Brien & Hodgins 1999, the
/// damping of the paper's deformation model): a damping stress that depends
/// only on how fast the element deforms, so rigid motions are not damped.
#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <icd/fem/stiffness_pattern.hpp>
#include <icd/fem/tet_mesh_data.hpp>

namespace icd::fem {

/// Strain-rate damping parameters: the viscous second Piola-Kirchhoff stress
/// S_v = phi tr(Edot) I + 2 psi Edot of the Green strain rate
/// Edot = sym(F^T Fdot), Fdot = Vs Dm^-1 (Vs: velocity differences of the
/// element, like Ds for positions). Both zero: no damping.
struct StrainRateDamping {
  double phi = 0;  ///< volumetric viscosity (O'Brien & Hodgins' phi), Pa s, >= 0
  double psi = 0;  ///< shear viscosity (O'Brien & Hodgins' psi), Pa s, >= 0
  bool enabled() const { return phi > 0 || psi > 0; }
};

/// Throws ParameterError naming the field when phi or psi is negative or not finite.
void validate(const StrainRateDamping& damping);

/// Adds the damping forces f_d = -sum_e V_e (F S_v) Dm^-T (distributed to the
/// nodes like the elastic forces; #V x 3, N) of velocities v at positions x
/// (#V x 3) to f. f_d is linear in v, vanishes for rigid velocities
/// v = w x x + t, and dissipates: v . f_d = -2 R(v) <= 0 with the Rayleigh
/// dissipation function R(v) = 1/2 sum_e V_e (2 psi |Edot|^2 + phi tr(Edot)^2),
/// f_d = -dR/dv. Sequential (deterministic).
void add_strain_rate_damping_forces(const TetMeshData& mesh, const StrainRateDamping& damping,
                                    const Eigen::Ref<const MatX3d>& x,
                                    const Eigen::Ref<const MatX3d>& v, Eigen::Ref<MatX3d> f);

/// Adds scale x D(x) to A, D = -df_d/dv (3#V x 3#V, symmetric positive
/// semi-definite, N s/m) the damping matrix at positions x, written in place
/// into A's values; A must have the layout of `pattern` (e.g. a copy of
/// ElasticForces::stiffness()). Backward Euler's Newton matrix uses it.
void add_strain_rate_damping_matrix(const TetMeshData& mesh, const StiffnessPattern& pattern,
                                    const StrainRateDamping& damping,
                                    const Eigen::Ref<const MatX3d>& x, double scale,
                                    Eigen::SparseMatrix<double>& A);

/// The Rayleigh dissipation function R(v) above, W (J/s): half the power the
/// damping forces dissipate.
double strain_rate_dissipation(const TetMeshData& mesh, const StrainRateDamping& damping,
                               const Eigen::Ref<const MatX3d>& x,
                               const Eigen::Ref<const MatX3d>& v);

}  // namespace icd::fem
