#pragma once
/// Reduction of the medial-sphere set to a few spheres covering a patch of
/// surface samples (one node of the sphere tree and its children).
#include <chrono>
#include <vector>

#include <Eigen/Core>

#include <icd/mesh/core/types.hpp>
#include <icd/mesh/spheres/cpu_clock.hpp>
#include <icd/mesh/spheres/medial_axis.hpp>
#include <icd/mesh/spheres/point_grid.hpp>

namespace icd::mesh {

/// A sphere fitted to surface samples: it contains every member sample s
/// with margin gap[s], i.e. |s - center| + gap[s] <= radius.
struct FittedSphere {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  double radius = 0;  ///< model units
  double depth = 0;   ///< distance from the centre to the surface (centre inside; 0 if unknown)
  /// Error bound radius - depth: no point of the sphere is farther than this
  /// from the object (a point of the sphere at distance radius from the centre
  /// is at most radius - depth beyond the surface along the ray from the centre).
  double error = 0;
  std::vector<int> members;  ///< sample indices the sphere covers (sorted)
  int tag = -1;              ///< caller's label, kept by every function here
};

/// The fixed data of a reduction: samples with their coverage margins, and
/// the candidate centres (medial spheres) with a grid over them.
struct ReductionProblem {
  const MatX3d& points;          ///< #S x 3 surface samples
  const Eigen::VectorXd& gap;    ///< #S coverage margins
  const MedialSpheres& medial;   ///< candidate centres and their depths
  const PointGrid& medial_grid;  ///< grid over medial.centers

  /// |s - c| + gap[s]: the radius a sphere centred at c needs to cover
  /// sample s with margin.
  double reach(int s, const Eigen::Vector3d& c) const {
    return (points.row(s).transpose() - c).norm() + gap[s];
  }
  /// The same for a sphere's centre.
  double reach(int s, const FittedSphere& sphere) const { return reach(s, sphere.center); }
};

/// Options of reduce_to_spheres().
struct ReductionOptions {
  int lloyd_iterations = 8;   ///< assignment / refit rounds after each split (>= 0)
  int max_candidates = 2500;  ///< candidate centres tried per refit (evenly thinned beyond)
  double depth_bias = 0.05;   ///< preference for deep centres when seeding a new sphere
  /// Past this process CPU time only the greedy splits run (no Lloyd rounds):
  /// the result is still valid.
  CpuClock::time_point deadline = CpuClock::time_point::max();
  /// Worker threads of one reduce_to_spheres() call (the assignment and the
  /// spheres' refits; >= 1). The result does not depend on it. The builder
  /// uses more than one only for the root's reduction, where there is one
  /// node to reduce.
  int threads = 1;
};

/// Fits one sphere to the samples `members`: the candidate centre with the
/// smallest error bound (max |s - c| + gap - depth(c), evaluated on the
/// extreme points of the members), then the exact radius over all members.
/// `hint` (may be null) restricts the candidates to those inside it; without
/// it the candidates inside the members' bounding ball are tried. Falls back
/// to the members' bounding ball (depth 0) when no candidate is found.
/// `extreme` (may be null): the members' extreme points when the caller
/// knows them (member_extreme_points or union_extreme_points; any order),
/// which saves the convex hull of all members.
FittedSphere fit_sphere(const ReductionProblem& problem, const std::vector<int>& members,
                        const FittedSphere* hint, const ReductionOptions& options,
                        const std::vector<Eigen::Vector3d>* extreme = nullptr);

/// For each direction (row of `dirs`), the member of `members` with the
/// largest value dirs(d, 0) * x + dirs(d, 1) * y + dirs(d, 2) * z (evaluated
/// left to right) over its sample (x, y, z) = points.row(member), the first
/// in the order of `members` on ties: what a scan of every member finds,
/// found faster by bucketing the members in the cells of a grid and
/// scanning only the cells whose bounding box can reach the best value
/// found. -1 for every direction when `members` is empty.
std::vector<int> farthest_members(const MatX3d& points, const std::vector<int>& members,
                                  const MatX3d& dirs);

/// The extreme points (convex hull vertices) of the samples `members`
/// (non-empty) as fit_sphere() uses them: every member when there are at
/// most 64, or when the members are coplanar.
std::vector<Eigen::Vector3d> member_extreme_points(const ReductionProblem& problem,
                                                   const std::vector<int>& members);

/// member_extreme_points(problem, members) for `members` = the union of two
/// sample sets whose member_extreme_points are `a` and `b`, computed from
/// those alone (a hull vertex of the union is one of a or b): the same
/// points, possibly in another order, at the cost of a hull of a and b.
std::vector<Eigen::Vector3d> union_extreme_points(const ReductionProblem& problem,
                                                  const std::vector<int>& members,
                                                  const std::vector<Eigen::Vector3d>& a,
                                                  const std::vector<Eigen::Vector3d>& b);

/// Moves the centre of `sphere` (members given) off the medial candidates
/// to lower its error bound max |s - c| + gap[s] - distance(c, surface):
/// compass search (6 axis steps, halved on failure, starting at a quarter of
/// the radius) with the exact distance from `oracle`, the centre kept inside.
/// Then refits the radius exactly over all members, and keeps the starting
/// sphere (radius refitted) when that has the lower error. Member sets over
/// 20000 samples are searched on their extreme points along 162 directions.
void polish_sphere(const ReductionProblem& problem, const MeshOracle& oracle, FittedSphere& sphere,
                   int max_evaluations = 80);

/// Reduces the medial set to k = 1 .. max_k spheres that together cover
/// `members` (non-empty): greedy splitting (a new sphere at the medial ball
/// touching the worst-covered sample) followed after each split by Lloyd
/// rounds: each sample goes to the sphere j minimizing |s - c_j| - depth_j
/// (this minimizes the worst error bound for fixed centres), then each
/// sphere's centre is refitted (fit_sphere). The best configuration seen
/// (lowest worst + mean error) is kept. Returns result[k - 1] = k spheres
/// (possibly fewer when a sphere lost all its samples), each sample in
/// exactly one sphere's members. Deterministic.
std::vector<std::vector<FittedSphere>> reduce_to_spheres(const ReductionProblem& problem,
                                                         const std::vector<int>& members, int max_k,
                                                         const ReductionOptions& options);

/// Lloyd rounds over an existing sphere set (no splitting): the samples of
/// all spheres are reassigned (rule of reduce_to_spheres) and each centre
/// refitted; keeps the best configuration (lowest worst + mean error).
/// Spheres that lose all their samples keep their place with empty members.
/// Used to optimise a whole tree level jointly across sibling groups.
void refine_jointly(const ReductionProblem& problem, std::vector<FittedSphere>& spheres,
                    const ReductionOptions& options);

/// Divides `members` among `spheres` (the rule of reduce_to_spheres: sample
/// s goes to the sphere minimizing |s - c| - depth) and refits every radius
/// so that each sphere covers its share with margin; centres and depths are
/// kept, errors updated, spheres left without samples removed.
void assign_and_refit(const ReductionProblem& problem, const std::vector<int>& members,
                      std::vector<FittedSphere>& spheres);

}  // namespace icd::mesh
