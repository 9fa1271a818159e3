#pragma once
/// Two copies of a mesh approaching each other (contact_tightness, issue 5):
/// the second copy's rigid motion, the last parameter at which a tree's leaf
/// pairs can overlap, and the search for the pose where the surfaces first
/// touch.
#include <functional>
#include <random>

#include <Eigen/Core>

#include <icd/collision/aabb_tree.hpp>
#include <icd/collision/sphere_tree.hpp>
#include <icd/mesh/core/types.hpp>

namespace icd::experiments {

/// The rigid motion of the second copy at parameter t: x -> R (x - c) + c + t u
/// (|u| = 1; larger t is farther along u).
struct ApproachPose {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  Eigen::Vector3d u = Eigen::Vector3d::UnitX();
  Eigen::Vector3d apply(const Eigen::Vector3d& x, double t) const {
    return R * (x - c) + c + t * u;
  }
};

/// A stream of random poses: a uniformly random rotation about `centre` and
/// a uniformly random direction each (seven normal draws). Same seed, same
/// poses.
class RandomApproachPoses {
 public:
  RandomApproachPoses(unsigned seed, const Eigen::Vector3d& centre)
      : m_rng(seed), m_centre(centre) {}
  ApproachPose next();

 private:
  std::mt19937 m_rng;
  std::normal_distribution<double> m_normal;  // (keeps the second value of each pair it draws)
  Eigen::Vector3d m_centre;
};

/// The largest t at which some leaf of `a` and some leaf of `b` moved by
/// `pose` overlap (closed spheres), -infinity when none ever does: past it no
/// leaf pair overlaps, so two surfaces the trees cover are apart.
double last_leaf_overlap(const collision::SphereTree& a, const collision::SphereTree& b,
                         const ApproachPose& pose);

/// `tree` with every sphere centre moved by `pose` at t.
collision::SphereTree moved(const collision::SphereTree& tree, const ApproachPose& pose, double t);

/// Where the surfaces first touch, coming from large t: `apart` is a t at
/// which they do not meet and `crossing` <= apart, within `tolerance` of it,
/// one at which they do. `found` is false when they meet at `start` already.
struct Touching {
  bool found = false;
  double apart = 0.0;
  double crossing = 0.0;
};

/// From `start` (meets(start) should be false), steps of `step` towards
/// smaller t until meets(t), then bisection down to `tolerance` (at most 60
/// halvings). Finds the first crossing a step of `step` can see: a contact
/// interval shorter than `step` may be stepped over. Throws ParameterError
/// for a step or tolerance that is not positive and finite.
Touching find_touching(const std::function<bool(double)>& meets, double start, double step,
                       double tolerance);

/// Exact surface contact of a mesh with a moved copy of itself (triangle
/// pairs through bounding-box trees; the copy's boxes refitted per call).
/// Keeps V and F by reference: they must outlive it.
class SelfApproach {
 public:
  SelfApproach(const MatX3d& V, const MatX3i& F);
  /// True when some triangle of the mesh and some triangle of the copy moved
  /// by `pose` at t intersect (closed triangles).
  bool meets(const ApproachPose& pose, double t);

 private:
  const MatX3d& m_V;
  const MatX3i& m_F;
  collision::AabbTree m_tree;
  MatX3d m_moved;
  collision::AabbTree m_moved_tree;
};

}  // namespace icd::experiments
