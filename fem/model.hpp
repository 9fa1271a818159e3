#pragma once
/// The physical model of one deformable object: elastic forces, lumped mass,
/// Rayleigh damping and boundary conditions (fixed nodes, external nodal
/// forces, gravity). Integrators and solvers act on it.
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include <icd/fem/forces.hpp>
#include <icd/fem/mass_scaling.hpp>
#include <icd/fem/strain_rate_damping.hpp>

namespace icd::fem {

/// Rayleigh damping C = alpha M + beta K(x).
struct RayleighDamping {
  double alpha = 0;  ///< mass-proportional coefficient, 1/s, >= 0
  double beta = 0;   ///< stiffness-proportional coefficient, s, >= 0
};

/// Options of a Model.
struct ModelOptions {
  RayleighDamping damping;
  /// O'Brien-Hodgins damping on the Green strain rate (in addition to Rayleigh).
  StrainRateDamping strain_rate_damping;
  Eigen::Vector3d gravity{0.0, 0.0, 0.0};  ///< m/s^2
  ForceOptions forces;
  /// Selective mass scaling at construction (off by default; the scenes turn
  /// it on, experiments/runner/scene.hpp). The added mass is mass: it feels
  /// gravity and Rayleigh alpha damping like the rest (fem/README.md).
  MassScaling mass_scaling;
};

/// One object. Positions and velocities (#V x 3) are passed in; the model
/// itself is stateless apart from boundary conditions and scratch space.
class Model {
 public:
  /// rest_positions V (#V x 3, m), tets T (#T x 4, positive). Throws InputError
  /// for a bad mesh and ParameterError for a bad material or options.
  Model(const Eigen::Ref<const MatX3d>& rest_positions, const Eigen::Ref<const MatX4i>& tets,
        const Material& material, const ModelOptions& options = {});

  int num_nodes() const { return m_forces.mesh().num_nodes; }
  const TetMeshData& mesh() const { return m_forces.mesh(); }
  const Material& material() const { return m_forces.material(); }
  ElasticForces& elastic() { return m_forces; }
  /// Lumped nodal masses (#V), kg, after any mass scaling: what the
  /// integrators, the stable-step estimate, energies and loads use.
  const Eigen::VectorXd& mass() const { return m_mass; }
  /// Replaces the nodal masses (#V, finite, > 0 kg, 0 only for a node in no
  /// tet; ParameterError naming the node otherwise), e.g. by
  /// apply_mass_scaling(); gravity loads follow.
  void set_masses(const Eigen::Ref<const Eigen::VectorXd>& mass);
  /// What ModelOptions::mass_scaling did (target_ratio 0: off).
  const MassScalingReport& mass_scaling() const { return m_mass_scaling; }

  /// Fixes the given nodes (their velocity and acceleration stay zero).
  /// Throws ParameterError naming an out-of-range node.
  void set_fixed_nodes(const std::vector<int>& nodes);
  /// Per-node flag (#V), 1 for fixed.
  const std::vector<char>& fixed_nodes() const { return m_fixed; }
  /// Per-dof flag (3#V), 1 for a dof of a fixed node.
  std::vector<char> fixed_dofs() const;
  /// External nodal forces (#V x 3, N), constant until changed; the coupling
  /// layer adds contact forces here. Throws ParameterError on a shape mismatch
  /// or a non-finite entry (naming the node).
  void set_external_forces(const Eigen::Ref<const MatX3d>& forces);
  const MatX3d& external_forces() const { return m_external; }
  void set_gravity(const Eigen::Vector3d& gravity);
  const Eigen::Vector3d& gravity() const { return m_gravity; }
  /// Throws ParameterError for negative or non-finite coefficients.
  void set_damping(const RayleighDamping& damping);
  const RayleighDamping& damping() const { return m_damping; }
  /// Throws ParameterError for negative or non-finite viscosities.
  void set_strain_rate_damping(const StrainRateDamping& damping);
  const StrainRateDamping& strain_rate_damping() const { return m_strain_rate_damping; }

  /// Total force on every node (#V x 3, N): f_int(x) + f_ext + m g - alpha m v
  /// - beta K(x) v + the strain-rate damping force; zero rows at fixed nodes.
  void total_force(const Eigen::Ref<const MatX3d>& x, const Eigen::Ref<const MatX3d>& v,
                   Eigen::Ref<MatX3d> f);
  /// Accelerations M^-1 total_force (#V x 3, m/s^2), zero at fixed nodes, in
  /// one pass over the nodes after the element loop. health (optional): the
  /// health of x from the same element pass (ElasticForces::compute_with_health).
  /// elastic (optional): f_int(x) already computed, see element_forces().
  /// oriented (optional): see element_forces().
  void acceleration(const Eigen::Ref<const MatX3d>& x, const Eigen::Ref<const MatX3d>& v,
                    Eigen::Ref<MatX3d> a, ElementHealth* health = nullptr,
                    const MatX3d* elastic = nullptr, bool* oriented = nullptr);
  /// The element part of total_force (#V x 3, N, overwritten): f_int(x) - beta
  /// K(x) v + the strain-rate damping force, at every node (fixed ones
  /// included); the nodal part, loads() - alpha m v at free nodes, is left to
  /// the caller's node pass (acceleration() and the fused integrator passes).
  /// elastic (optional): f_int(x) already computed (e.g. by a health check at
  /// x), used instead of a force evaluation. health: as in acceleration().
  /// oriented (optional, not with health or elastic): whether every det F of
  /// x is > 0, from the same element pass
  /// (ElasticForces::compute_with_orientation_check).
  void element_forces(const Eigen::Ref<const MatX3d>& x, const Eigen::Ref<const MatX3d>& v,
                      Eigen::Ref<MatX3d> f, ElementHealth* health = nullptr,
                      const MatX3d* elastic = nullptr, bool* oriented = nullptr);
  /// Conservative nodal loads f_ext + m g at free nodes, 0 at fixed ones (#V x 3), N.
  const MatX3d& loads() const { return m_load; }
  /// 1 / lumped mass per node (#V), 1/kg.
  const Eigen::VectorXd& inverse_mass() const { return m_inv_mass; }
  /// Per dof 3i+c (3#V), for flat node passes that the compiler vectorises:
  /// the lumped mass of node i (kg), its inverse (1/kg), and a bit mask, all
  /// ones at the dofs of free nodes and 0 at those of fixed ones (AND-ing a
  /// double's bits with it zeroes fixed dofs exactly, also a NaN, without a
  /// branch).
  const Eigen::VectorXd& dof_mass() const { return m_dof_mass; }
  const Eigen::VectorXd& dof_inverse_mass() const { return m_dof_inv_mass; }
  const std::vector<std::uint64_t>& dof_free_mask() const { return m_dof_free; }
  /// Kinetic energy 1/2 sum m |v|^2, J; not finite if any entry of v is not.
  double kinetic_energy(const Eigen::Ref<const MatX3d>& v) const;
  /// Potential of the conservative loads: -sum (f_ext + m g) . x over the free
  /// nodes, J; not finite if any entry of x (fixed nodes included) is not.
  double load_potential(const Eigen::Ref<const MatX3d>& x) const;

 private:
  ElasticForces m_forces;
  Eigen::VectorXd m_mass;
  Eigen::VectorXd m_inv_mass;  ///< 1/m (#V)
  std::vector<char> m_fixed;
  Eigen::VectorXd m_dof_mass, m_dof_inv_mass;  ///< 3#V each
  std::vector<std::uint64_t> m_dof_free;       ///< 3#V
  void update_load();
  void update_dofs();
  MatX3d m_external;
  MatX3d m_load;  ///< f_ext + m g at free nodes, 0 at fixed ones (#V x 3), N
  Eigen::Vector3d m_gravity;
  RayleighDamping m_damping;
  StrainRateDamping m_strain_rate_damping;
  MassScalingReport m_mass_scaling;
  MatX3d m_scratch;
};

}  // namespace icd::fem
