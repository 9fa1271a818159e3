#include <icd/fem/model.hpp>

#include <cassert>
#include <cmath>
#include <string>

#include <icd/fem/mass.hpp>
#include <icd/mesh/core/error.hpp>

namespace icd::fem {

Model::Model(const Eigen::Ref<const MatX3d>& rest_positions, const Eigen::Ref<const MatX4i>& tets,
             const Material& material, const ModelOptions& options)
    : m_forces(make_tet_mesh_data(rest_positions, tets), material, options.forces) {
  m_mass = lumped_mass(m_forces.mesh(), material.density);
  m_fixed.assign(num_nodes(), 0);
  m_inv_mass = m_mass.cwiseInverse();
  m_external = MatX3d::Zero(num_nodes(), 3);
  m_scratch.resize(num_nodes(), 3);
  update_dofs();
  set_gravity(options.gravity);
  set_damping(options.damping);
  set_strain_rate_damping(options.strain_rate_damping);
  validate(options.mass_scaling);
  if (options.mass_scaling.target_ratio > 0)
    m_mass_scaling = apply_mass_scaling(*this, rest_positions, options.mass_scaling);
}

void Model::set_masses(const Eigen::Ref<const Eigen::VectorXd>& mass) {
  if (mass.size() != num_nodes())
    throw ParameterError("fem::Model::set_masses: " + std::to_string(mass.size()) +
                         " masses, expected #V = " + std::to_string(num_nodes()));
  for (int i = 0; i < num_nodes(); ++i)
    if (!((mass[i] > 0 || (mass[i] == 0 && m_mass[i] == 0)) && std::isfinite(mass[i])))
      throw ParameterError("fem::Model::set_masses: mass of node " + std::to_string(i) + " = " +
                           std::to_string(mass[i]) +
                           " is invalid: expected finite and > 0 kg (0 only for a node in no tet)");
  m_mass = mass;
  m_inv_mass = m_mass.cwiseInverse();
  update_dofs();
  update_load();
}

void Model::set_strain_rate_damping(const StrainRateDamping& damping) {
  validate(damping);
  m_strain_rate_damping = damping;
}

void Model::set_fixed_nodes(const std::vector<int>& nodes) {
  std::vector<char> fixed(num_nodes(), 0);
  for (int i : nodes) {
    if (i < 0 || i >= num_nodes())
      throw ParameterError("fem::Model::set_fixed_nodes: node " + std::to_string(i) +
                           " is out of range [0, " + std::to_string(num_nodes()) + ")");
    fixed[i] = 1;
  }
  m_fixed = std::move(fixed);
  update_dofs();
  update_load();
}

void Model::update_dofs() {
  const int n = num_nodes();
  m_dof_mass.resize(3 * n);
  m_dof_inv_mass.resize(3 * n);
  m_dof_free.resize(3 * static_cast<size_t>(n));
  for (int i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) {
      m_dof_mass[3 * i + c] = m_mass[i];
      m_dof_inv_mass[3 * i + c] = m_inv_mass[i];
      m_dof_free[3 * i + c] = m_fixed[i] ? std::uint64_t{0} : ~std::uint64_t{0};
    }
}

void Model::update_load() {
  m_load.resize(num_nodes(), 3);
  for (int i = 0; i < num_nodes(); ++i)
    for (int c = 0; c < 3; ++c)
      m_load(i, c) = m_fixed[i] ? 0.0 : m_external(i, c) + m_mass[i] * m_gravity[c];
}

std::vector<char> Model::fixed_dofs() const {
  std::vector<char> d(3 * static_cast<size_t>(num_nodes()));
  for (int i = 0; i < num_nodes(); ++i) d[3 * i] = d[3 * i + 1] = d[3 * i + 2] = m_fixed[i];
  return d;
}

void Model::set_external_forces(const Eigen::Ref<const MatX3d>& forces) {
  if (forces.rows() != num_nodes())
    throw ParameterError("fem::Model::set_external_forces: " + std::to_string(forces.rows()) +
                         " rows, expected #V = " + std::to_string(num_nodes()));
  for (int i = 0; i < num_nodes(); ++i)
    if (!forces.row(i).allFinite())
      throw ParameterError("fem::Model::set_external_forces: force on node " + std::to_string(i) +
                           " is not finite");
  m_external = forces;
  update_load();
}

void Model::set_gravity(const Eigen::Vector3d& gravity) {
  if (!gravity.allFinite()) throw ParameterError("fem::Model: gravity is not finite");
  m_gravity = gravity;
  update_load();
}

void Model::set_damping(const RayleighDamping& damping) {
  if (!(damping.alpha >= 0) || !(damping.beta >= 0) || !std::isfinite(damping.alpha) ||
      !std::isfinite(damping.beta))
    throw ParameterError("fem::RayleighDamping: alpha = " + std::to_string(damping.alpha) +
                         ", beta = " + std::to_string(damping.beta) +
                         " are invalid: expected finite values >= 0");
  m_damping = damping;
}

void Model::total_force(const Eigen::Ref<const MatX3d>& x, const Eigen::Ref<const MatX3d>& v,
                        Eigen::Ref<MatX3d> f) {
  m_forces.compute(x, f);
  if (m_damping.beta > 0) {
    m_forces.differential(x, v, m_scratch);  // -K v
    f += m_damping.beta * m_scratch;
  }
  add_strain_rate_damping_forces(mesh(), m_strain_rate_damping, x, v, f);
  const int n = num_nodes();
  for (int i = 0; i < n; ++i) {
    if (m_fixed[i]) {
      f.row(i).setZero();
      continue;
    }
    const double m = m_mass[i];
    for (int c = 0; c < 3; ++c)
      f(i, c) += m_external(i, c) + m * (m_gravity[c] - m_damping.alpha * v(i, c));
  }
}

void Model::element_forces(const Eigen::Ref<const MatX3d>& x, const Eigen::Ref<const MatX3d>& v,
                           Eigen::Ref<MatX3d> f, ElementHealth* health, const MatX3d* elastic,
                           bool* oriented) {
  if (elastic) {
    assert(!health && !oriented && elastic->rows() == num_nodes());
    f = *elastic;
  } else if (health) {
    assert(!oriented);
    *health = m_forces.compute_with_health(x, f);
  } else if (oriented) {
    *oriented = m_forces.compute_with_orientation_check(x, f);
  } else {
    m_forces.compute(x, f);
  }
  if (m_damping.beta > 0) {
    m_forces.differential(x, v, m_scratch);  // -K v
    f += m_damping.beta * m_scratch;
  }
  add_strain_rate_damping_forces(mesh(), m_strain_rate_damping, x, v, f);
}

void Model::acceleration(const Eigen::Ref<const MatX3d>& x, const Eigen::Ref<const MatX3d>& v,
                         Eigen::Ref<MatX3d> a, ElementHealth* health, const MatX3d* elastic,
                         bool* oriented) {
  element_forces(x, v, a, health, elastic, oriented);
  const int n = num_nodes();
  const double alpha = m_damping.alpha;
  const double* load = m_load.data();
  const double* vp = v.data();
  const long vs = v.outerStride();
  for (int i = 0; i < n; ++i) {
    const double w = m_inv_mass[i], m = m_mass[i];
    double* ai = a.data() + a.outerStride() * i;
    if (m_fixed[i]) {  // exactly zero, even where the elastic force is not finite
      ai[0] = ai[1] = ai[2] = 0.0;
      continue;
    }
    for (int c = 0; c < 3; ++c) ai[c] = w * (ai[c] + load[3 * i + c] - m * alpha * vp[vs * i + c]);
  }
}

double Model::kinetic_energy(const Eigen::Ref<const MatX3d>& v) const {
  return 0.5 * (m_mass.array() * v.rowwise().squaredNorm().array()).sum();
}

double Model::load_potential(const Eigen::Ref<const MatX3d>& x) const {
  return -(m_load.array() * x.array()).sum();
}

}  // namespace icd::fem
