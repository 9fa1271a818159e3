#include <icd/fem/static_solver.hpp>

#include <cmath>

#include <icd/fem/newton_system.hpp>
#include <icd/mesh/core/error.hpp>

namespace icd::fem {

NewtonReport StaticSolver::solve(Model& model, MatX3d& x, const NewtonOptions& options) {
  const int n = model.num_nodes();
  if (x.rows() != n)
    throw ParameterError("fem::StaticSolver::solve: x has " + std::to_string(x.rows()) +
                         " rows, expected #V = " + std::to_string(n));
  const auto fixed = model.fixed_dofs();
  const MatX3d zero = MatX3d::Zero(n, 3);
  MatX3d g(n, 3), g_try(n, 3), x_try(n, 3);
  NewtonReport rep;
  for (int i = 0; i < n; ++i)
    if (!model.fixed_nodes()[i])
      rep.reference +=
          (model.external_forces().row(i) + model.mass()[i] * model.gravity().transpose())
              .squaredNorm();
  rep.reference = std::sqrt(rep.reference);
  const double size = (model.mesh().rest_positions.colwise().maxCoeff() -
                       model.mesh().rest_positions.colwise().minCoeff())
                          .norm();
  auto potential = [&](const MatX3d& y) {
    return model.elastic().energy(y) + model.load_potential(y);
  };

  model.total_force(x, zero, g);
  double gn = flat(g).norm(), pot = potential(x);
  Eigen::VectorXd dx;
  for (rep.iterations = 0; rep.iterations < options.max_iterations; ++rep.iterations) {
    if (gn <= options.tolerance * rep.reference) {
      rep.converged = true;
      break;
    }
    m_A = model.elastic().stiffness(x);
    apply_dirichlet(m_A, fixed);
    rep.max_shift =
        std::max(rep.max_shift, solve_with_shift(m_solver, m_A, m_shifted, flat(g), dx));
    if (dx.cwiseAbs().maxCoeff() <= 1e-14 * size) {
      rep.converged = true;
      break;
    }
    // Backtracking: accept when the potential or the residual decreases. If
    // neither does at a residual already near the tolerance, the iteration has
    // reached the round-off floor of the internal forces: stop, converged.
    double t = 1.0;
    bool accepted = false;
    for (int ls = 0; ls < 30 && !accepted; ++ls, t *= 0.5) {
      x_try = x;
      flat(x_try) += t * dx;
      const double pt = potential(x_try);
      model.total_force(x_try, zero, g_try);
      const double gt = flat(g_try).norm();
      if ((std::isfinite(pt) && pt < pot) || gt < gn) {
        x.swap(x_try);
        g.swap(g_try);
        gn = gt;
        pot = pt;
        accepted = true;
      } else if (ls == 0 && gn <= std::sqrt(options.tolerance) * rep.reference) {
        break;
      }
    }
    if (!accepted) {
      rep.converged = gn <= std::sqrt(options.tolerance) * rep.reference;
      break;
    }
  }
  rep.residual = gn;
  return rep;
}

}  // namespace icd::fem
