#include <icd/fem/backward_euler.hpp>

#include <cmath>

#include <icd/fem/newton_system.hpp>
#include <icd/mesh/core/error.hpp>

namespace icd::fem {

NewtonReport BackwardEulerStepper::step(Model& model, State& s, double h,
                                        const NewtonOptions& options) {
  if (!(h > 0) || !std::isfinite(h))
    throw ParameterError("fem::BackwardEulerStepper::step: h = " + std::to_string(h) +
                         " must be > 0");
  const int n = model.num_nodes();
  const Eigen::VectorXd& m = model.mass();
  const auto fixed = model.fixed_dofs();
  const RayleighDamping damp = model.damping();
  MatX3d f(n, 3), v1 = s.v, x1 = s.x + h * s.v, r(n, 3), v_try(n, 3), x_try(n, 3), r_try(n, 3);

  auto residual = [&](const MatX3d& x, const MatX3d& v, MatX3d& out) {
    model.total_force(x, v, f);
    for (int i = 0; i < n; ++i)
      out.row(i) = model.fixed_nodes()[i] ? Eigen::RowVector3d::Zero().eval()
                                          : (m[i] * (v.row(i) - s.v.row(i)) - h * f.row(i)).eval();
    return flat(out).norm();
  };
  NewtonReport rep;
  {
    MatX3d f0(n, 3), zero = MatX3d::Zero(n, 3);
    model.elastic().compute(s.x, f0);
    double load = 0;
    for (int i = 0; i < n; ++i)
      if (!model.fixed_nodes()[i])
        load += (model.external_forces().row(i) + m[i] * model.gravity().transpose()).squaredNorm();
    Eigen::VectorXd mv = (s.v.array().colwise() * m.array()).matrix().reshaped<Eigen::RowMajor>();
    rep.reference = mv.norm() + h * (flat(f0).norm() + std::sqrt(load));
  }
  double rn = residual(x1, v1, r);
  Eigen::VectorXd dv;
  for (rep.iterations = 0; rep.iterations < options.max_iterations; ++rep.iterations) {
    if (rn <= options.tolerance * rep.reference) {
      rep.converged = true;
      break;
    }
    const auto& K = model.elastic().stiffness(x1);
    if (m_A.nonZeros() != K.nonZeros()) m_A = K;
    const double ck = h * h + h * damp.beta;
    Eigen::Map<Eigen::VectorXd>(m_A.valuePtr(), m_A.nonZeros()) =
        ck * Eigen::Map<const Eigen::VectorXd>(K.valuePtr(), K.nonZeros());
    for (int i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c)
        m_A.coeffRef(3 * i + c, 3 * i + c) += m[i] * (1.0 + h * damp.alpha);
    add_strain_rate_damping_matrix(model.mesh(), model.elastic().pattern(),
                                   model.strain_rate_damping(), x1, h, m_A);
    apply_dirichlet(m_A, fixed);
    const Eigen::VectorXd rhs = -flat(r);
    rep.max_shift = std::max(rep.max_shift, solve_with_shift(m_solver, m_A, m_shifted, rhs, dv));
    // Backtracking on the residual norm. No decrease at all means the
    // round-off floor of the forces was reached: converged if the residual is
    // within sqrt(tolerance) of the reference, failed otherwise.
    double t = 1.0;
    bool accepted = false;
    for (int ls = 0; ls < 8 && !accepted; ++ls, t *= 0.5) {
      v_try = v1;
      flat(v_try) += t * dv;
      x_try = s.x + h * v_try;
      const double rt = residual(x_try, v_try, r_try);
      if (rt < rn) {
        v1.swap(v_try);
        x1.swap(x_try);
        r.swap(r_try);
        rn = rt;
        accepted = true;
      }
    }
    if (!accepted) {
      rep.converged = rn <= std::sqrt(options.tolerance) * rep.reference;
      break;
    }
  }
  rep.residual = rn;
  s.x = x1;
  s.v = v1;
  return rep;
}

}  // namespace icd::fem
