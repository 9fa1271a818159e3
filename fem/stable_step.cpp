#include <icd/fem/stable_step.hpp>

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <random>
#include <vector>

#include <Eigen/Eigenvalues>

#include <icd/mesh/core/error.hpp>

namespace icd::fem {
namespace {

bool rk4_stable(std::complex<double> z) {
  const std::complex<double> R = 1.0 + z * (1.0 + z * (0.5 + z * (1.0 / 6.0 + z / 24.0)));
  return std::norm(R) <= (1.0 + 1e-12) * (1.0 + 1e-12);  // |R|^2: no hypot
}

// A damped mode: the roots of s^2 + c s + omega^2 = 0. RK4 at step h is
// stable for it when |R(h s)| <= 1 at both roots.
struct Rk4Mode {
  std::complex<double> s1, s2;
  Rk4Mode(double omega, double c) {
    const std::complex<double> disc = std::sqrt(std::complex<double>(c * c - 4 * omega * omega, 0.0));
    s1 = 0.5 * (-c + disc);
    s2 = 0.5 * (-c - disc);
  }
  bool stable(double h) const { return rk4_stable(h * s1) && rk4_stable(h * s2); }
  // The largest stable step (the stable steps form an interval [0, limit]).
  double limit() const {
    const double scale = std::max(std::abs(s1), std::abs(s2));
    if (scale == 0) return std::numeric_limits<double>::infinity();
    double lo = 0, hi = 1.0 / scale;
    while (stable(hi)) {
      lo = hi;
      hi *= 2;
    }
    for (int i = 0; i < 56; ++i) {  // the bracket [lo, 2 lo] to 2^-55 relative
      const double mid = 0.5 * (lo + hi);
      (stable(mid) ? lo : hi) = mid;
    }
    return lo;
  }
};

double symplectic_euler_mode_limit(double omega, double c) {
  double h = (std::sqrt(c * c + 4 * omega * omega) - c) / (omega * omega);
  if (c > 0) h = std::min(h, 2.0 / c);
  return h;
}

}  // namespace

double stable_step_limit(Integrator integrator, double omega_max, const RayleighDamping& damping,
                         double max_damping_rate) {
  if (!(omega_max > 0) || !std::isfinite(omega_max))
    throw ParameterError("fem::stable_step_limit: omega_max = " + std::to_string(omega_max) +
                         " must be finite and > 0");
  if (!(max_damping_rate >= 0) || !std::isfinite(max_damping_rate))
    throw ParameterError("fem::stable_step_limit: max_damping_rate = " +
                         std::to_string(max_damping_rate) + " must be finite and >= 0");
  if (integrator == Integrator::BackwardEuler) return std::numeric_limits<double>::infinity();
  double limit = std::numeric_limits<double>::infinity();
  // Extra modal damping in [0, max_damping_rate]: 9 levels (0 and the maximum included).
  const int levels = max_damping_rate > 0 ? 8 : 0;
  // From the top mode down (it usually sets the limit): a mode for which
  // the limit found so far is already stable cannot lower it (the stable
  // steps of a mode form an interval [0, its limit], as Rk4Mode::limit's
  // search assumes), so RK4 skips its bisection (one stability test
  // instead of ~60: the limit was ~20 % of a many_objects contact cycle).
  for (int k = 96; k >= 0; --k) {  // omega_max * 10^(0 .. -6)
    const double omega = omega_max * std::pow(10.0, -6.0 * (96 - k) / 96.0);
    for (int j = 0; j <= levels; ++j) {
      const double c = damping.alpha + damping.beta * omega * omega +
                       (levels ? max_damping_rate * j / levels : 0.0);
      if (integrator == Integrator::RK4) {
        const Rk4Mode mode(omega, c);
        if (std::isfinite(limit) && mode.stable(limit)) continue;
        limit = std::min(limit, mode.limit());
      } else {
        limit = std::min(limit, symplectic_euler_mode_limit(omega, c));
      }
    }
  }
  return limit;
}

namespace {

// Top eigenpair of a symmetric operator on the free dofs by Lanczos with full
// reorthogonalisation; apply(q, out) computes out = A q for A = M^-1/2 B M^-1/2.
template <class Apply>
FrequencyEstimate lanczos_top(Apply&& apply, const Eigen::VectorXd& free,
                              const FrequencyOptions& options, Eigen::VectorXd* warm,
                              double* theta_out) {
  const int ndof = static_cast<int>(free.size());
  const int nfree = static_cast<int>(free.sum());
  FrequencyEstimate est;
  *theta_out = 0;
  if (nfree == 0) return est;
  Eigen::VectorXd q0(ndof);
  if (warm && warm->size() == ndof && warm->cwiseProduct(free).norm() > 0) {
    q0 = warm->cwiseProduct(free);
  } else {
    std::mt19937 gen(12345);
    std::uniform_real_distribution<double> dist(-1.0, 1.0);
    for (int k = 0; k < ndof; ++k) q0[k] = dist(gen);
    q0 = q0.cwiseProduct(free);
  }
  q0.normalize();

  const int kmax = std::min(options.max_iterations, nfree);
  std::vector<Eigen::VectorXd> Q{q0};
  std::vector<double> alpha, beta;
  Eigen::VectorXd w, ritz;
  double theta = 0;
  Eigen::VectorXd s_top;
  Eigen::MatrixXd S;  // eigenvectors of the last tridiagonal matrix
  for (int j = 0; j < kmax; ++j) {
    apply(Q[j], w);
    alpha.push_back(Q[j].dot(w));
    for (int pass = 0; pass < 2; ++pass)  // full reorthogonalisation, twice is enough
      for (const auto& qi : Q) w -= qi.dot(w) * qi;
    beta.push_back(w.norm());
    const int k = j + 1;
    Eigen::MatrixXd T = Eigen::MatrixXd::Zero(k, k);
    for (int i = 0; i < k; ++i) {
      T(i, i) = alpha[i];
      if (i + 1 < k) T(i, i + 1) = T(i + 1, i) = beta[i];
    }
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(T);
    theta = es.eigenvalues()[k - 1];
    S = es.eigenvectors();
    s_top = S.col(k - 1);
    est.iterations = k;
    est.residual = std::abs(beta[j] * s_top[k - 1]) / std::max(std::abs(theta), 1e-300);
    if (est.residual <= options.tolerance || beta[j] <= 1e-14 * std::abs(theta)) {
      est.converged = true;
      break;
    }
    Q.push_back(w / beta[j]);
  }
  if (warm) {  // the sum of the top warm_modes Ritz vectors (orthonormal)
    const int k = static_cast<int>(S.cols());
    ritz = Eigen::VectorXd::Zero(ndof);
    for (int m = 0; m < std::min(options.warm_modes, k); ++m)
      for (int i = 0; i < k; ++i) ritz += S(i, k - 1 - m) * Q[i];
    *warm = ritz;
  }
  *theta_out = theta;
  return est;
}

void check_options(const FrequencyOptions& options) {
  if (options.max_iterations < 1 || !(options.contact_stiffness >= 0) || !(options.tolerance > 0) ||
      options.warm_modes < 1)
    throw ParameterError(
        "fem::FrequencyOptions: expected max_iterations >= 1, tolerance > 0, "
        "contact_stiffness >= 0 and warm_modes >= 1");
}

// Free-dof mask and M^-1/2 per dof.
void free_dofs(const Model& model, Eigen::VectorXd& free, Eigen::VectorXd& inv_sqrt_m) {
  const int n = model.num_nodes();
  free = Eigen::VectorXd::Zero(3 * n);
  inv_sqrt_m.resize(3 * n);
  for (int i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) {
      free[3 * i + c] = model.fixed_nodes()[i] ? 0.0 : 1.0;
      inv_sqrt_m[3 * i + c] = 1.0 / std::sqrt(model.mass()[i]);
    }
}

}  // namespace

FrequencyEstimate estimate_max_frequency(Model& model, const Eigen::Ref<const MatX3d>& x,
                                         const FrequencyOptions& options, Eigen::VectorXd* warm,
                                         const MatX3d* forces_at_x) {
  check_options(options);
  const int n = model.num_nodes();
  const int ndof = 3 * n;
  Eigen::VectorXd free, inv_sqrt_m;
  free_dofs(model, free, inv_sqrt_m);
  MatX3d u(n, 3), du(n, 3);
  // Forward differences: f(x) once, then one force evaluation per product.
  MatX3d f0, xe;
  double step_scale = 0;  // eps = step_scale / max |u_i|
  if (options.finite_difference_products) {
    xe.resize(n, 3);
    if (forces_at_x) {
      if (forces_at_x->rows() != n)
        throw ParameterError("fem::estimate_max_frequency: forces_at_x has " +
                             std::to_string(forces_at_x->rows()) +
                             " rows, expected #V = " + std::to_string(n));
      f0 = *forces_at_x;
    } else {
      f0.resize(n, 3);
      model.elastic().compute(x, f0);
    }
    const double mean_volume = model.mesh().rest_volume.mean();
    step_scale = 1e-7 * std::cbrt(6.0 * std::max(mean_volume, 0.0));
  }
  auto apply = [&](const Eigen::VectorXd& q, Eigen::VectorXd& out) {
    Eigen::Map<Eigen::VectorXd>(u.data(), ndof) = inv_sqrt_m.cwiseProduct(q).cwiseProduct(free);
    const double umax = u.cwiseAbs().maxCoeff();
    if (options.finite_difference_products && umax > 0 && step_scale > 0) {
      const double eps = step_scale / umax;
      xe = x + eps * u;
      model.elastic().compute(xe, du);
      du = (du - f0) / eps;  // -K u + O(eps)
    } else {
      model.elastic().differential(x, u, du);  // -K u
    }
    out = (-inv_sqrt_m.cwiseProduct(Eigen::Map<const Eigen::VectorXd>(du.data(), ndof)) +
           options.contact_stiffness * inv_sqrt_m.cwiseProduct(inv_sqrt_m).cwiseProduct(q))
              .cwiseProduct(free);
  };
  double theta = 0;
  FrequencyEstimate est = lanczos_top(apply, free, options, warm, &theta);
  if (!std::isfinite(theta))
    throw NumericalError(
        "fem::estimate_max_frequency: the stiffness of the current state is not finite");
  est.omega_max = std::sqrt(std::max(theta, 0.0));
  est.omega_bound = est.omega_max * std::sqrt(1.0 + est.residual);
  return est;
}

double estimate_max_damping_rate(Model& model, const Eigen::Ref<const MatX3d>& x,
                                 const FrequencyOptions& options, Eigen::VectorXd* warm) {
  check_options(options);
  if (!model.strain_rate_damping().enabled()) return 0;
  const int n = model.num_nodes();
  const int ndof = 3 * n;
  Eigen::VectorXd free, inv_sqrt_m;
  free_dofs(model, free, inv_sqrt_m);
  MatX3d u(n, 3), fd(n, 3);
  auto apply = [&](const Eigen::VectorXd& q, Eigen::VectorXd& out) {
    Eigen::Map<Eigen::VectorXd>(u.data(), ndof) = inv_sqrt_m.cwiseProduct(q).cwiseProduct(free);
    fd.setZero();
    add_strain_rate_damping_forces(model.mesh(), model.strain_rate_damping(), x, u, fd);  // -D u
    out = (-inv_sqrt_m.cwiseProduct(Eigen::Map<const Eigen::VectorXd>(fd.data(), ndof)))
              .cwiseProduct(free);
  };
  double theta = 0;
  const FrequencyEstimate est = lanczos_top(apply, free, options, warm, &theta);
  if (!std::isfinite(theta))
    throw NumericalError(
        "fem::estimate_max_damping_rate: the damping matrix of the current state is not finite");
  return std::max(theta, 0.0) * (1.0 + est.residual);
}

}  // namespace icd::fem
