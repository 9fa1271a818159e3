#pragma once
/// Internal elastic forces, energy, force differential and tangent stiffness
/// of linear tetrahedra for every MaterialModel (paper section 3).
#include <limits>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/SparseCore>

#include <icd/fem/material.hpp>
#include <icd/fem/stiffness_pattern.hpp>
#include <icd/fem/tet_mesh_data.hpp>

namespace icd::fem {
namespace lanes {
struct LaneLoopInput;
enum class LaneCheck;
}  // namespace lanes

/// Options of the element loops.
struct ForceOptions {
  /// Threads for the element loops (>= 1). Results are bitwise identical for
  /// any count: elements write to a per-element buffer and each node sums its
  /// element contributions in increasing element order (the order of the
  /// sequential scatter), energies are summed per fixed chunk of elements.
  int num_threads = 1;
  int polar_max_iterations = 20;   ///< corotational: bound on polar iterations per element
  double polar_tolerance = 1e-12;  ///< corotational: stop when the rotation update < this (rad)
};

/// Energy and inversion state of a configuration.
struct ElementHealth {
  double energy = 0;                 ///< total elastic energy W(x), J
  double min_det_f = 0;              ///< smallest det F over the elements (J = current/rest volume)
  int min_det_f_element = -1;        ///< element where it occurs
  int first_nonfinite_element = -1;  ///< first element whose energy is NaN/Inf, -1 if none
};

/// Elastic forces of a tet mesh for one material. Positions x are #V x 3
/// (metres); forces are #V x 3 (N); dofs are numbered 3i+c. Not thread-safe
/// (keeps scratch buffers and, for corotational, the per-element warm-start rotations).
class ElasticForces {
 public:
  /// Throws ParameterError for an invalid material or options.
  ElasticForces(TetMeshData mesh, const Material& material, const ForceOptions& options = {});

  const TetMeshData& mesh() const { return m_mesh; }
  const Material& material() const { return m_material; }
  const ForceOptions& options() const { return m_options; }
  /// Sets the thread count (>= 1, else ParameterError).
  void set_num_threads(int num_threads);

  /// f = -dW/dx (overwritten). Throws ParameterError on a shape mismatch.
  void compute(const Eigen::Ref<const MatX3d>& x, Eigen::Ref<MatX3d> f);
  /// Same as compute() and, from the same pass over the elements, the health
  /// of x: smallest det F and its element as health(x), the energy equal to
  /// health(x).energy up to the summation order (deterministic for any thread
  /// count); where an energy is not finite, health(x) itself (naming the first
  /// such element). Costs a fraction of a second pass.
  ElementHealth compute_with_health(const Eigen::Ref<const MatX3d>& x, Eigen::Ref<MatX3d> f);
  /// Same as compute() and, from the same pass over the elements, whether
  /// every element keeps its orientation: true iff det F > 0 for all elements
  /// (false where one is <= 0 or not finite, i.e. NaN). The cheap part of
  /// compute_with_health() (no energy, no smallest det F or its element):
  /// 0-2 ns/tet over compute() with the AVX2 lane loops against 3-8 for
  /// compute_with_health() (bench_fem BM_Kernels kind 4 vs 1); the element
  /// is named by health().
  bool compute_with_orientation_check(const Eigen::Ref<const MatX3d>& x, Eigen::Ref<MatX3d> f);
  /// Same as compute() and returns the elastic energy W(x) = sum_e V_e psi(F_e), J.
  double compute_with_energy(const Eigen::Ref<const MatX3d>& x, Eigen::Ref<MatX3d> f);
  /// Elastic energy W(x), J.
  double energy(const Eigen::Ref<const MatX3d>& x);
  /// Energy, smallest det F and non-finite elements of configuration x.
  ElementHealth health(const Eigen::Ref<const MatX3d>& x);
  /// df = -K(x) dx: the force change along dx without assembling K (matrix-free).
  void differential(const Eigen::Ref<const MatX3d>& x, const Eigen::Ref<const MatX3d>& dx,
                    Eigen::Ref<MatX3d> df);
  /// Tangent stiffness K(x) = d2W/dx2 (3#V x 3#V, symmetric), assembled by
  /// writing values in place into the precomputed pattern (no triplets).
  const Eigen::SparseMatrix<double>& stiffness(const Eigen::Ref<const MatX3d>& x);
  /// The sparsity pattern used by stiffness().
  const StiffnessPattern& pattern() const { return m_pattern; }

 private:
  template <class Op>
  void for_chunks(Op&& op);
  void check_shape(const Eigen::Ref<const MatX3d>& x, const char* what) const;
  void gather(double* f);
  template <bool kEnergy>
  double compute_impl(const Eigen::Ref<const MatX3d>& x, Eigen::Ref<MatX3d> f);
  void differential_fast(const double* x, const double* dx, double* df);
  /// Lane-loop input at positions x: element forces go to `forces` directly
  /// with one thread, else to the per-element scratch for gather().
  lanes::LaneLoopInput lane_input(const double* x, double* forces);
  /// kCheck None: forces only; Full: *health; Orientation: *oriented.
  template <lanes::LaneCheck kCheck>
  void compute_fast(const Eigen::Ref<const MatX3d>& x, Eigen::Ref<MatX3d> f, ElementHealth* health,
                    bool* oriented = nullptr);
  struct ChunkHealth {
    double min_det = std::numeric_limits<double>::infinity();
    int min_element = -1;
    int nonfinite = -1;
    bool oriented = true;  ///< every det F > 0 (Orientation checks)
  };

  TetMeshData m_mesh;
  Material m_material;
  ForceOptions m_options;
  double m_mu = 0, m_lambda = 0;
  StiffnessPattern m_pattern;
  Eigen::SparseMatrix<double> m_stiffness;
  std::vector<Eigen::Quaterniond> m_rotations;  // corotational warm starts
  std::vector<double> m_element_forces;         // #T x 12 scratch for threaded scatter
  std::vector<int> m_node_offset, m_node_slot;  // node -> element slots (CSR, ascending element)
  std::vector<double> m_chunk_sum;
  std::vector<ChunkHealth> m_chunk_health;
  std::vector<double> m_lane_blocks;  // lanes::Block per 8 elements (SoA Dm^-1, volume)
};

}  // namespace icd::fem
