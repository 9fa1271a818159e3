#pragma once
/// Continuous collision detection between two query instants (not in the
/// paper, whose queries sample the motion at the end of each cycle and so
/// miss objects that cross each other between two queries).
///
/// Each sphere of a tree is swept along the segment from its centre at the
/// start of the interval to its centre at the end, with its largest radius
/// (SweptSphere). Two swept spheres are tested in relative motion: they touch
/// during the interval iff the distance between their centres, linear in
/// time, comes within the sum of their radii. If every point of a sphere's
/// surface patch moves along with the sphere (linear motion over the
/// interval; exact for a translation), a point where the two surfaces touch
/// at any instant lies in a pair of spheres that touch at that instant, so a
/// traversal that prunes only pairs that never touch finds it.
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include <icd/collision/sphere_tree.hpp>
#include <icd/collision/traversal.hpp>

namespace icd::collision {

/// A sphere moving linearly over an interval: centre (x, y, z) + t (dx, dy, dz)
/// for t in [0, 1], radius at most r throughout.
struct SweptSphere {
  double x = 0, y = 0, z = 0, dx = 0, dy = 0, dz = 0, r = 0;
};

/// True when swept spheres a and b come within r_a + r_b of each other at
/// some common instant t in [0, 1].
bool swept_overlap(const SweptSphere& a, const SweptSphere& b);

/// out[i] sweeps from[i] to to[i] (radius max(r_from, r_to)); when `via` is
/// not empty, the radius also covers via[i] (a sphere passed near the
/// segment, e.g. the actual end of a cycle whose sweep runs to a predicted
/// position). Returns the largest motion of a sphere, max_i |c_to - c_from| +
/// max(0, r_to - r_from) (model units). Throws ParameterError when sizes differ.
double sweep_spheres(std::span<const Sphere> from, std::span<const Sphere> to,
                     std::vector<SweptSphere>& out, std::span<const Sphere> via = {});

/// A tree that does not move: swept spheres with no motion.
void still_spheres(std::span<const Sphere> spheres, std::vector<SweptSphere>& out);

/// Options of swept_contact().
struct SweptRequest {
  /// Sphere tests before giving up (-1: no limit); giving up answers "touched".
  int64_t budget_tests = -1;
  /// Wall seconds before giving up (infinity: no limit); giving up answers "touched".
  double budget_seconds = std::numeric_limits<double>::infinity();
};

/// What swept_contact() found.
struct SweptResult {
  bool touched = false;  ///< some leaf pair touches during the interval (or the budget ran out)
  bool gave_up = false;  ///< the budget ran out before the answer was known
  int64_t tests = 0;     ///< swept sphere tests done
  NodePair first;        ///< the first touching leaf pair found (when touched and not gave_up)
};

/// Do trees a and b (topology; swept spheres sa, sb, one per node) touch at
/// some instant of the interval? Depth-first, splitting the larger sphere of
/// a pair; stops at the first touching leaf pair. `stack` is reused storage.
SweptResult swept_contact(const SphereTree& a, std::span<const SweptSphere> sa,
                          const SphereTree& b, std::span<const SweptSphere> sb,
                          const SweptRequest& request, std::vector<NodePair>& stack);

}  // namespace icd::collision
