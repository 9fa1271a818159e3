#pragma once
/// The true error of a sphere (how far its surface sticks out of the object,
/// measured on sphere-surface points) and a centre polish that lowers it
/// while the sphere keeps covering its samples (issue 5).
#include <array>
#include <vector>

#include <Eigen/Core>

#include <icd/mesh/core/types.hpp>
#include <icd/mesh/spheres/mesh_oracle.hpp>
#include <icd/mesh/spheres/reduction.hpp>

namespace icd::mesh {

/// `count` (>= 1) unit vectors on a Fibonacci spiral, #count x 3: nearly
/// uniform, with no symmetry shared with the icosahedral probe sets of the
/// evaluation (probe_directions), so that fitting against them does not fit
/// the evaluation's directions. Throws ParameterError for count < 1.
MatX3d spiral_directions(int count);

/// Largest distance to the surface of the points center + radius * d (d: the
/// rows of `directions`, unit vectors) that lie outside the closed mesh behind
/// `oracle`, 0 when none does (the error of evaluate_sphere_tree with other
/// directions). Distances are taken for every point, inside tests only for
/// the farthest ones until one lies outside.
double sphere_protrusion(const MeshOracle& oracle, const Eigen::Vector3d& center, double radius,
                         const Eigen::Ref<const MatX3d>& directions);

/// r(c) = max over `members` of |s - c| + gap[s] (the smallest radius that
/// covers them with margin from centre c), for a centre that moves in small
/// steps. It keeps a shell of members, rebuilt around c0 when c leaves the
/// ball of radius `reach` around it: every member that can be the farthest
/// from such a c (a member with |s - c0| + gap < R0 - 2 reach is nearer to c
/// than r(c) >= R0 - reach). The shell is stored in bands of decreasing reach
/// from c0; an evaluation stops before the first band whose largest reach
/// from c0 plus |c - c0| (with a margin for rounding) is below the largest
/// reach found. The result is the exact maximum over all members (the same
/// number). `problem` and `members` must outlive it.
class CoverRadius {
 public:
  /// Throws ParameterError for no members or a negative reach.
  CoverRadius(const ReductionProblem& problem, const std::vector<int>& members, double reach);

  /// r(c).
  double operator()(const Eigen::Vector3d& c);

  /// The caller will stay within `reach` of `c` for a while: a thinner shell
  /// is built around c when that halves the current reach or more.
  void narrow(const Eigen::Vector3d& c, double reach);

 private:
  static constexpr int kBands = 8;
  void rebuild(const Eigen::Vector3d& c0);

  const ReductionProblem& m_problem;
  const std::vector<int>& m_members;
  double m_reach;
  Eigen::Vector3d m_c0 = Eigen::Vector3d::Zero();
  double m_r0 = 0;                       // largest reach from c0
  std::vector<double> m_reach0;          // scratch of rebuild(): each member's reach from c0
  std::vector<Eigen::Vector4d> m_shell;  // point, gap
  std::array<size_t, kBands + 1> m_band_begin{};  // band b: m_shell[begin[b], begin[b + 1])
  std::array<double, kBands> m_band_max{};        // largest reach from c0 in each band
};

/// Options of polish_protrusion().
struct ProtrusionPolishOptions {
  /// Sphere-surface points per evaluation in the search (spiral_directions,
  /// turned by a rotation drawn from the sphere's index; >= 1).
  int search_directions = 128;
  /// Points of the acceptance check (spiral_directions, not turned; >= 1):
  /// a move is kept only when the protrusion measured on these drops.
  int check_directions = 600;
  int max_evaluations = 80;    ///< search evaluations per sphere (>= 0)
  double initial_step = 0.08;  ///< first step of the pattern search (fraction of the radius, > 0)
  double min_step = 0.004;     ///< the search stops below this step (fraction of the radius, > 0)
};

/// What polish_protrusion() did to one sphere.
struct ProtrusionPolishResult {
  /// True when the search found a better centre, so that both were measured
  /// on the check points; before and after are 0 otherwise.
  bool checked = false;
  double before = 0;    ///< protrusion on the check points at the start
  double after = 0;     ///< and at the end (<= before)
  int evaluations = 0;  ///< search evaluations spent
  bool moved = false;   ///< true when the centre (and radius) changed
};

/// Moves the centre of `sphere` (its members given) to lower its protrusion
/// (sphere_protrusion) by a pattern search (steps towards the 26 neighbours
/// of a cube cell, the last successful direction tried first, the step halved
/// when none improves), the radius being a function of the centre: the smallest that
/// covers every member with margin, r(c) = max |s - c| + gap[s]. Every member
/// stays covered with margin; the move is kept only when the protrusion on the
/// check points drops (so it never rises). Updates centre, radius, depth
/// (distance to the surface when the centre is inside, else 0) and the error
/// bound (radius - depth). `seed` picks the search rotation (deterministic).
/// Throws ParameterError for invalid options.
ProtrusionPolishResult polish_protrusion(const ReductionProblem& problem, const MeshOracle& oracle,
                                         FittedSphere& sphere, unsigned seed,
                                         const ProtrusionPolishOptions& options = {});

/// polish_protrusion() with given search and check directions (unit rows, at
/// least one each) instead of the spiral sets; `options`' direction counts
/// are ignored. For experiments that show how a sphere fitted against one
/// fixed direction set looks on others (the builder does not use it).
ProtrusionPolishResult polish_protrusion_on(const ReductionProblem& problem,
                                            const MeshOracle& oracle, FittedSphere& sphere,
                                            const Eigen::Ref<const MatX3d>& search_directions,
                                            const Eigen::Ref<const MatX3d>& check_directions,
                                            const ProtrusionPolishOptions& options = {});

}  // namespace icd::mesh
