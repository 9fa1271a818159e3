#include <icd/fem/forces.hpp>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <string>
#include <type_traits>

#include <icd/fem/constitutive.hpp>
#include <icd/fem/element_kernels.hpp>
#include <icd/fem/lane_kernels.hpp>
#include <icd/fem/lane_loops.hpp>
#include <icd/fem/polar.hpp>
#include <icd/mesh/core/error.hpp>

namespace icd::fem {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;

constexpr int kChunk = 512;  // elements per chunk: fixed, so sums do not depend on threads

// A law that needs only F.
template <class Law>
struct PlainEval {
  Law law;
  Matrix3d stress(int, const Matrix3d& F, double* psi) const {
    if (psi) *psi = law.energy(F);
    return law.stress(F);
  }
  double energy(int, const Matrix3d& F) const { return law.energy(F); }
  auto tangent(int, const Matrix3d& F) const {
    return [this, F](const Matrix3d& dF) { return law.stress_differential(F, dF); };
  }
};

// Corotational: polar rotation per element, warm-started from the last call.
struct CorotationalEval {
  CorotationalLaw law;
  Eigen::Quaterniond* rotations;
  int max_iterations;
  double tolerance;
  Matrix3d rotation(int e, const Matrix3d& F) const {
    polar_rotation(F, rotations[e], max_iterations, tolerance);
    return rotations[e].toRotationMatrix();
  }
  Matrix3d stress(int e, const Matrix3d& F, double* psi) const {
    const Matrix3d R = rotation(e, F);
    if (psi) *psi = law.energy(F, R);
    return law.stress(F, R);
  }
  double energy(int e, const Matrix3d& F) const { return law.energy(F, rotation(e, F)); }
  auto tangent(int e, const Matrix3d& F) const {
    const Matrix3d R = rotation(e, F);
    return [this, F, R](const Matrix3d& dF) { return law.stress_differential(F, R, dF); };
  }
};

// Ds = [x1-x0, x2-x0, x3-x0] of element e from a row-major #V x 3 array with row stride s.
inline Matrix3d edge_matrix(const double* x, long s, const int* t) {
  const double* p0 = x + s * t[0];
  Matrix3d Ds;
  for (int c = 0; c < 3; ++c) {
    const double* p = x + s * t[c + 1];
    Ds(0, c) = p[0] - p0[0];
    Ds(1, c) = p[1] - p0[1];
    Ds(2, c) = p[2] - p0[2];
  }
  return Ds;
}

// Writes the four nodal vectors of H = -V P Dm^-T: f_a = H.col(a-1), f_0 = -sum.
inline void write_element(const Matrix3d& H, double* out) {
  for (int r = 0; r < 3; ++r) {
    out[3 + r] = H(r, 0);
    out[6 + r] = H(r, 1);
    out[9 + r] = H(r, 2);
    out[r] = -(H(r, 0) + H(r, 1) + H(r, 2));
  }
}

}  // namespace

ElasticForces::ElasticForces(TetMeshData mesh, const Material& material,
                             const ForceOptions& options)
    : m_mesh(std::move(mesh)),
      m_material(material),
      m_options(options),
      m_pattern(m_mesh.num_nodes, m_mesh.tets) {
  const Lame l = lame_parameters(material);
  m_mu = l.mu;
  m_lambda = l.lambda;
  set_num_threads(options.num_threads);
  if (options.polar_max_iterations < 1)
    throw ParameterError(
        "fem::ForceOptions.polar_max_iterations = " + std::to_string(options.polar_max_iterations) +
        " is invalid: expected >= 1");
  m_stiffness = m_pattern.zero_matrix();
  m_rotations.assign(m_mesh.num_tets(), Eigen::Quaterniond::Identity());
  m_element_forces.resize(12 * static_cast<size_t>(m_mesh.num_tets()));
  m_node_offset.assign(m_mesh.num_nodes + 1, 0);
  for (int e = 0; e < m_mesh.num_tets(); ++e)
    for (int a = 0; a < 4; ++a) ++m_node_offset[m_mesh.tets(e, a) + 1];
  for (int i = 0; i < m_mesh.num_nodes; ++i) m_node_offset[i + 1] += m_node_offset[i];
  m_node_slot.resize(m_node_offset.back());
  std::vector<int> fill(m_node_offset.begin(), m_node_offset.end() - 1);
  for (int e = 0; e < m_mesh.num_tets(); ++e)  // ascending e: the sequential scatter order
    for (int a = 0; a < 4; ++a) m_node_slot[fill[m_mesh.tets(e, a)]++] = 12 * e + 3 * a;
  m_chunk_sum.resize((m_mesh.num_tets() + kChunk - 1) / kChunk);
  m_chunk_health.resize(m_chunk_sum.size());
  static_assert(kChunk % lanes::kLanes == 0, "chunks hold whole lane blocks");
  static_assert(sizeof(lanes::Block) == sizeof(double) * 10 * lanes::kLanes,
                "Block is plain doubles");
  const int nblocks = (m_mesh.num_tets() + lanes::kLanes - 1) / lanes::kLanes;
  m_lane_blocks.assign(static_cast<size_t>(nblocks) * 10 * lanes::kLanes, 0.0);
  for (int e = 0; e < m_mesh.num_tets(); ++e) {
    auto* b = reinterpret_cast<lanes::Block*>(m_lane_blocks.data()) + e / lanes::kLanes;
    const int lane = e % lanes::kLanes;
    for (int k = 0; k < 9; ++k) b->dinv[k][lane] = m_mesh.dm_inv[e].data()[k];
    b->volume[lane] = m_mesh.rest_volume[e];
  }
}

void ElasticForces::set_num_threads(int num_threads) {
  if (num_threads < 1)
    throw ParameterError("fem::ForceOptions.num_threads = " + std::to_string(num_threads) +
                         " is invalid: expected >= 1");
  m_options.num_threads = num_threads;
}

void ElasticForces::check_shape(const Eigen::Ref<const MatX3d>& x, const char* what) const {
  if (x.rows() != m_mesh.num_nodes)
    throw ParameterError(std::string("fem::ElasticForces: ") + what + " has " +
                         std::to_string(x.rows()) +
                         " rows, expected #V = " + std::to_string(m_mesh.num_nodes));
}

template <class Op>
void ElasticForces::for_chunks(Op&& op) {
  const int nt = m_mesh.num_tets();
  const int nchunks = static_cast<int>(m_chunk_sum.size());
  if (m_options.num_threads == 1) {
    for (int c = 0; c < nchunks; ++c)
      m_chunk_sum[c] = op(c * kChunk, std::min(nt, (c + 1) * kChunk));
    return;
  }
#pragma omp parallel for schedule(static) num_threads(m_options.num_threads)
  for (int c = 0; c < nchunks; ++c) m_chunk_sum[c] = op(c * kChunk, std::min(nt, (c + 1) * kChunk));
}

void ElasticForces::gather(double* f) {
  const int nv = m_mesh.num_nodes;
  const double* buf = m_element_forces.data();
#pragma omp parallel for schedule(static) num_threads(m_options.num_threads)
  for (int i = 0; i < nv; ++i) {
    double s0 = 0, s1 = 0, s2 = 0;
    for (int k = m_node_offset[i]; k < m_node_offset[i + 1]; ++k) {
      const double* c = buf + m_node_slot[k];
      s0 += c[0];
      s1 += c[1];
      s2 += c[2];
    }
    f[3 * i] = s0;
    f[3 * i + 1] = s1;
    f[3 * i + 2] = s2;
  }
}

// Calls fn(eval) with the evaluator of the current material.
#define ICD_FEM_DISPATCH(fn)                                     \
  switch (m_material.model) {                                    \
    case MaterialModel::Linear: {                                \
      const PlainEval<LinearLaw> ev{{m_mu, m_lambda}};           \
      return fn(ev);                                             \
    }                                                            \
    case MaterialModel::StVK: {                                  \
      const PlainEval<StVKLaw> ev{{m_mu, m_lambda}};             \
      return fn(ev);                                             \
    }                                                            \
    case MaterialModel::StableNeoHookean: {                      \
      const PlainEval<StableNeoHookeanLaw> ev{{m_mu, m_lambda}}; \
      return fn(ev);                                             \
    }                                                            \
    case MaterialModel::Corotational: {                          \
      const CorotationalEval ev{{m_mu, m_lambda},                \
                                m_rotations.data(),              \
                                m_options.polar_max_iterations,  \
                                m_options.polar_tolerance};      \
      return fn(ev);                                             \
    }                                                            \
  }                                                              \
  throw ParameterError("fem::ElasticForces: unknown material model");

template <bool kEnergy>
double ElasticForces::compute_impl(const Eigen::Ref<const MatX3d>& x, Eigen::Ref<MatX3d> f) {
  check_shape(x, "positions");
  check_shape(f, "forces");
  const double* xp = x.data();
  const long xs = x.outerStride();
  const int* T = m_mesh.tets.data();
  const Matrix3d* Dinv = m_mesh.dm_inv.data();
  const double* vol = m_mesh.rest_volume.data();
  const bool direct = m_options.num_threads == 1 && f.outerStride() == 3;
  double* fp = f.data();
  double* buf = m_element_forces.data();
  auto run = [&](const auto& ev) {
    for_chunks([&](int begin, int end) {
      double sum = 0;
      for (int e = begin; e < end; ++e) {
        const Matrix3d F = edge_matrix(xp, xs, T + 4 * e) * Dinv[e];
        double psi = 0;
        const Matrix3d P = ev.stress(e, F, kEnergy ? &psi : nullptr);
        const Matrix3d H = (-vol[e]) * (P * Dinv[e].transpose());
        if (kEnergy) sum += vol[e] * psi;
        if (direct) {
          double out[12];
          write_element(H, out);
          for (int a = 0; a < 4; ++a) {
            double* fa = fp + 3 * T[4 * e + a];
            fa[0] += out[3 * a];
            fa[1] += out[3 * a + 1];
            fa[2] += out[3 * a + 2];
          }
        } else {
          write_element(H, buf + 12 * static_cast<size_t>(e));
        }
      }
      return sum;
    });
    return 0.0;
  };
  if (direct) f.setZero();
  [&]() -> double { ICD_FEM_DISPATCH(run) }();
  if (!direct) {
    if (f.outerStride() == 3) {
      gather(fp);
    } else {
      MatX3d tmp(f.rows(), 3);
      gather(tmp.data());
      f = tmp;
    }
  }
  double energy = 0;
  if (kEnergy)
    for (double s : m_chunk_sum) energy += s;
  return energy;
}

void ElasticForces::compute(const Eigen::Ref<const MatX3d>& x, Eigen::Ref<MatX3d> f) {
  check_shape(x, "positions");
  check_shape(f, "forces");
  if (x.outerStride() != 3 || f.outerStride() != 3) {
    compute_impl<false>(x, f);
    return;
  }
  compute_fast<lanes::LaneCheck::None>(x, f, nullptr);
}

ElementHealth ElasticForces::compute_with_health(const Eigen::Ref<const MatX3d>& x,
                                                 Eigen::Ref<MatX3d> f) {
  check_shape(x, "positions");
  check_shape(f, "forces");
  if (x.outerStride() != 3 || f.outerStride() != 3) {
    compute_impl<false>(x, f);
    return health(x);
  }
  ElementHealth h;
  compute_fast<lanes::LaneCheck::Full>(x, f, &h);
  return h;
}

bool ElasticForces::compute_with_orientation_check(const Eigen::Ref<const MatX3d>& x,
                                                   Eigen::Ref<MatX3d> f) {
  check_shape(x, "positions");
  check_shape(f, "forces");
  if (x.outerStride() != 3 || f.outerStride() != 3) {
    compute_impl<false>(x, f);
    const ElementHealth h = health(x);
    return h.min_det_f > 0;  // NaN compares false
  }
  bool oriented = true;
  compute_fast<lanes::LaneCheck::Orientation>(x, f, nullptr, &oriented);
  return oriented;
}

template <lanes::LaneCheck kCheck>
void ElasticForces::compute_fast(const Eigen::Ref<const MatX3d>& x, Eigen::Ref<MatX3d> f,
                                 ElementHealth* health, bool* oriented) {
  constexpr bool kHealth = kCheck == lanes::LaneCheck::Full;
  constexpr bool kOrientation = kCheck == lanes::LaneCheck::Orientation;
  // The hot path: 8-lane SoA kernels (lane_kernels.hpp) or, for corotational,
  // scalar kernels (element_kernels.hpp); one instantiation per model.
  const double* xp = x.data();
  const int* T = m_mesh.tets.data();
  const double* dinv = m_mesh.dm_inv.data()->data();
  const double* vol = m_mesh.rest_volume.data();
  const bool direct = m_options.num_threads == 1;
  double* fp = f.data();
  double* buf = m_element_forces.data();
  const double mu = m_mu, lambda = m_lambda;
  Eigen::Quaterniond* rot = m_rotations.data();
  const int max_it = m_options.polar_max_iterations;
  const double tol = m_options.polar_tolerance;
  ChunkHealth* chunk_health = m_chunk_health.data();
  auto scatter = [&](int e, const double* out) {
    if (!direct) {
      std::copy(out, out + 12, buf + 12 * static_cast<size_t>(e));
      return;
    }
    const int* t = T + 4 * e;
    for (int a = 0; a < 4; ++a) {
      double* fa = fp + 3 * t[a];
      fa[0] += out[3 * a];
      fa[1] += out[3 * a + 1];
      fa[2] += out[3 * a + 2];
    }
  };
  auto run = [&](auto model_tag) {
    constexpr MaterialModel kModel = decltype(model_tag)::value;
    if constexpr (kModel != MaterialModel::Corotational) {
      // 8 elements at a time in lane loops (lane_loops.hpp); scatter in element order.
      const lanes::LaneLoopInput in = lane_input(xp, fp);
      for_chunks([&](int begin, int end) {
        lanes::LaneRangeHealth rh;
        lanes::force_range<kModel, kCheck>(in, begin, end, &rh);
        if constexpr (kHealth) {
          ChunkHealth ch;
          ch.min_det = rh.min_det;
          ch.min_element = rh.min_element;
          ch.nonfinite = std::isfinite(rh.energy) ? -1 : begin;  // located by health() on failure
          chunk_health[begin / kChunk] = ch;
        }
        if constexpr (kOrientation) chunk_health[begin / kChunk].oriented = rh.oriented;
        return rh.energy;
      });
      return;
    }
    for_chunks([&](int begin, int end) {
      double sum = 0;
      ChunkHealth ch;
      for (int e = begin; e < end; ++e) {
        const int* t = T + 4 * e;
        const double* D = dinv + 9 * static_cast<size_t>(e);
        double F[9], P[9], H[9], R[9];
        kernels::deformation_gradient(xp + 3 * t[0], xp + 3 * t[1], xp + 3 * t[2], xp + 3 * t[3], D,
                                      F);
        kernels::corotational_stress(F, mu, lambda, rot[e], max_it, tol, P, R);
        if constexpr (kHealth) {
          const double J = kernels::determinant(F);
          if (J < ch.min_det) {
            ch.min_det = J;
            ch.min_element = e;
          }
          sum += vol[e] * kernels::corotational_energy(F, R, mu, lambda);
        }
        if constexpr (kOrientation) ch.oriented = ch.oriented && kernels::determinant(F) > 0;
        kernels::nodal_forces(P, D, vol[e], H);
        double out[12];
        for (int r = 0; r < 3; ++r) {
          out[3 + r] = H[3 * r];
          out[6 + r] = H[3 * r + 1];
          out[9 + r] = H[3 * r + 2];
          out[r] = -(H[3 * r] + H[3 * r + 1] + H[3 * r + 2]);
        }
        scatter(e, out);
      }
      if constexpr (kHealth) {
        ch.nonfinite = std::isfinite(sum) ? -1 : begin;
        chunk_health[begin / kChunk] = ch;
      }
      if constexpr (kOrientation) chunk_health[begin / kChunk].oriented = ch.oriented;
      return sum;
    });
  };
  if (direct) f.setZero();
  switch (m_material.model) {
    case MaterialModel::Linear:
      run(std::integral_constant<MaterialModel, MaterialModel::Linear>{});
      break;
    case MaterialModel::Corotational:
      run(std::integral_constant<MaterialModel, MaterialModel::Corotational>{});
      break;
    case MaterialModel::StVK:
      run(std::integral_constant<MaterialModel, MaterialModel::StVK>{});
      break;
    case MaterialModel::StableNeoHookean:
      run(std::integral_constant<MaterialModel, MaterialModel::StableNeoHookean>{});
      break;
  }
  if (!direct) gather(fp);
  if constexpr (kHealth) {
    ElementHealth& h = *health;
    h = ElementHealth{};
    h.min_det_f = std::numeric_limits<double>::infinity();
    bool nonfinite = false;
    for (size_t c = 0; c < m_chunk_sum.size(); ++c) {
      h.energy += m_chunk_sum[c];
      const ChunkHealth& ch = m_chunk_health[c];
      if (ch.min_element >= 0 && ch.min_det < h.min_det_f) {
        h.min_det_f = ch.min_det;
        h.min_det_f_element = ch.min_element;
      }
      nonfinite = nonfinite || ch.nonfinite >= 0;
    }
    // A NaN/Inf somewhere (a failing state): the separate pass names the first element exactly.
    if (nonfinite || !std::isfinite(h.energy)) h = this->health(x);
  }
  if constexpr (kOrientation) {
    bool all = true;
    for (size_t c = 0; c < m_chunk_sum.size(); ++c) all = all && m_chunk_health[c].oriented;
    *oriented = all;
  }
}

double ElasticForces::compute_with_energy(const Eigen::Ref<const MatX3d>& x, Eigen::Ref<MatX3d> f) {
  return compute_impl<true>(x, f);
}

double ElasticForces::energy(const Eigen::Ref<const MatX3d>& x) { return health(x).energy; }

ElementHealth ElasticForces::health(const Eigen::Ref<const MatX3d>& x) {
  check_shape(x, "positions");
  const double* xp = x.data();
  const long xs = x.outerStride();
  const int* T = m_mesh.tets.data();
  const double* dinv = m_mesh.dm_inv.data()->data();
  ElementHealth h;
  h.min_det_f = std::numeric_limits<double>::infinity();
  const CorotationalEval corot{{m_mu, m_lambda},
                               m_rotations.data(),
                               m_options.polar_max_iterations,
                               m_options.polar_tolerance};
  // Sequential; energies summed per chunk in the chunk order of the force loop.
  for (int c = 0; c * kChunk < m_mesh.num_tets(); ++c) {
    double sum = 0;
    for (int e = c * kChunk; e < std::min(m_mesh.num_tets(), (c + 1) * kChunk); ++e) {
      const int* t = T + 4 * e;
      double F[9];
      kernels::deformation_gradient(xp + xs * t[0], xp + xs * t[1], xp + xs * t[2], xp + xs * t[3],
                                    dinv + 9 * static_cast<size_t>(e), F);
      const double J = kernels::determinant(F);
      if (J < h.min_det_f || (std::isnan(J) && h.min_det_f_element < 0)) {
        h.min_det_f = J;
        h.min_det_f_element = e;
      }
      double psi = 0;
      switch (m_material.model) {
        case MaterialModel::Linear:
          psi = kernels::linear_energy(F, m_mu, m_lambda);
          break;
        case MaterialModel::StVK:
          psi = kernels::stvk_energy(F, m_mu, m_lambda);
          break;
        case MaterialModel::StableNeoHookean:
          psi = kernels::stable_neo_hookean_energy(F, J, m_mu, m_lambda);
          break;
        case MaterialModel::Corotational:
          psi = corot.energy(e, Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(F));
          break;
      }
      const double w = m_mesh.rest_volume[e] * psi;
      if (!std::isfinite(w) && h.first_nonfinite_element < 0) h.first_nonfinite_element = e;
      sum += w;
    }
    h.energy += sum;
  }
  return h;
}

void ElasticForces::differential(const Eigen::Ref<const MatX3d>& x,
                                 const Eigen::Ref<const MatX3d>& dx, Eigen::Ref<MatX3d> df) {
  check_shape(x, "positions");
  check_shape(dx, "displacements");
  check_shape(df, "force differential");
  const double* xp = x.data();
  const double* dp = dx.data();
  const long xs = x.outerStride(), ds = dx.outerStride();
  const int* T = m_mesh.tets.data();
  double* buf = m_element_forces.data();
  if (xs == 3 && ds == 3 && df.outerStride() == 3 &&
      m_material.model != MaterialModel::Corotational) {
    differential_fast(xp, dp, df.data());
    return;
  }
  auto run = [&](const auto& ev) {
    for_chunks([&](int begin, int end) {
      for (int e = begin; e < end; ++e) {
        const Matrix3d& Dinv = m_mesh.dm_inv[e];
        const Matrix3d F = edge_matrix(xp, xs, T + 4 * e) * Dinv;
        const Matrix3d dF = edge_matrix(dp, ds, T + 4 * e) * Dinv;
        const Matrix3d dP = ev.tangent(e, F)(dF);
        write_element((-m_mesh.rest_volume[e]) * (dP * Dinv.transpose()),
                      buf + 12 * static_cast<size_t>(e));
      }
      return 0.0;
    });
    return 0.0;
  };
  [&]() -> double { ICD_FEM_DISPATCH(run) }();
  if (df.outerStride() == 3) {
    gather(df.data());
  } else {
    MatX3d tmp(df.rows(), 3);
    gather(tmp.data());
    df = tmp;
  }
}

lanes::LaneLoopInput ElasticForces::lane_input(const double* x, double* forces) {
  lanes::LaneLoopInput in;
  in.x = x;
  in.tets = m_mesh.tets.data();
  in.blocks = reinterpret_cast<const lanes::Block*>(m_lane_blocks.data());
  in.mu = m_mu;
  in.lambda = m_lambda;
  in.forces = m_options.num_threads == 1 ? forces : nullptr;
  in.element_forces = m_element_forces.data();
  return in;
}

void ElasticForces::differential_fast(const double* xp, const double* dp, double* df) {
  // 8-lane kernels (lane_kernels.hpp); the Eigen laws of constitutive.hpp are the reference.
  const bool direct = m_options.num_threads == 1;
  const lanes::LaneLoopInput in = lane_input(xp, df);
  auto run = [&](auto model_tag) {
    constexpr MaterialModel kModel = decltype(model_tag)::value;
    for_chunks([&](int begin, int end) {
      lanes::differential_range<kModel>(in, dp, begin, end);
      return 0.0;
    });
  };
  if (direct) std::fill_n(df, 3 * static_cast<size_t>(m_mesh.num_nodes), 0.0);
  switch (m_material.model) {
    case MaterialModel::Linear:
      run(std::integral_constant<MaterialModel, MaterialModel::Linear>{});
      break;
    case MaterialModel::StVK:
      run(std::integral_constant<MaterialModel, MaterialModel::StVK>{});
      break;
    case MaterialModel::StableNeoHookean:
      run(std::integral_constant<MaterialModel, MaterialModel::StableNeoHookean>{});
      break;
    case MaterialModel::Corotational:
      assert(false && "corotational uses the Eigen path");
      break;
  }
  if (!direct) gather(df);
}

const Eigen::SparseMatrix<double>& ElasticForces::stiffness(const Eigen::Ref<const MatX3d>& x) {
  check_shape(x, "positions");
  const double* xp = x.data();
  const long xs = x.outerStride();
  double* val = m_stiffness.valuePtr();
  std::fill_n(val, m_stiffness.nonZeros(), 0.0);
  auto run = [&](const auto& ev) {
    for (int e = 0; e < m_mesh.num_tets(); ++e) {
      const int* t = m_mesh.tets.data() + 4 * e;
      const Matrix3d& Dinv = m_mesh.dm_inv[e];
      const Matrix3d F = edge_matrix(xp, xs, t) * Dinv;
      const auto dP = ev.tangent(e, F);
      const Eigen::Matrix<double, 4, 3> G = m_mesh.shape_gradients(e);
      for (int b = 0; b < 4; ++b)
        for (int c = 0; c < 3; ++c) {
          Matrix3d dF = Matrix3d::Zero();
          dF.row(c) = G.row(b);
          double col[12];  // column (b, c) of K_e = V dP Dm^-T, node 0 = -sum
          write_element((-m_mesh.rest_volume[e]) * (dP(dF) * Dinv.transpose()), col);
          for (int a = 0; a < 4; ++a) {
            double* block =
                val + m_pattern.block_offset(e, a, b) + c * m_pattern.column_length(t[b]);
            // K = -df/dx, and write_element wrote -(V dP Dm^-T) columns.
            block[0] -= col[3 * a];
            block[1] -= col[3 * a + 1];
            block[2] -= col[3 * a + 2];
          }
        }
    }
    return 0.0;
  };
  [&]() -> double { ICD_FEM_DISPATCH(run) }();
  return m_stiffness;
}

}  // namespace icd::fem
