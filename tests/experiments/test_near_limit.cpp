// The near-limit loops of the collision benchmark (experiments/studies/
// collision/near_limit.hpp) must do exactly the library's work: the same
// spheres after the update (bitwise) and the same leaf pairs, in the same
// order, and the same number of sphere tests as collide()'s full traversal,
// on a few deformed frames of two overlapping objects.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include <icd/collision/sphere_update.hpp>
#include <icd/collision/traversal.hpp>

#include "experiments/studies/collision/near_limit.hpp"
#include "experiments/studies/collision/workloads.hpp"

namespace icd::collision::experiments {
namespace {

bool bitwise_equal(const std::vector<Sphere>& x, const std::vector<Sphere>& y) {
  return x.size() == y.size() && std::memcmp(x.data(), y.data(), x.size() * sizeof(Sphere)) == 0;
}

TEST(CollisionStudies, NearLimitLoopsMatchTheLibrary) {
  for (int levels : {3, 5}) {
    // Unit icospheres overlapping (the benchmark's own workload builder).
    Object a = icosphere_object(3, 1.0, {0, 0, 0}, levels),
           b = icosphere_object(3, 1.0, {1.3, 0.4, 0.1}, levels);
    const PackedTree pa(a.tree), pb(b.tree);
    NearLimitUpdate nlu;
    NearLimitTraversal nlt;
    CollisionResult res;
    std::vector<Sphere> outa(a.tree.spheres.size()), outb(b.tree.spheres.size());
    int64_t total_pairs = 0;
    for (int frame = 0; frame < 4; ++frame) {
      const MatX3d xa = deform(a.coarse_rest, 0.08, 0.4 * frame),
                   xb = deform(b.coarse_rest, 0.08, 0.4 * frame + 1.0);
      for (bool ratio : {true, false}) {
        SphereUpdateOptions o;
        o.mode = ratio ? SphereUpdateMode::PaperRatio : SphereUpdateMode::DisplacementBound;
        update_spheres(a.tree, a.coarse_rest, xa, o);
        update_spheres(b.tree, b.coarse_rest, xb, o);
        nlu.run(a.tree, a.coarse_rest.data(), xa.data(), a.coarse_rest.rows(), ratio, outa.data());
        nlu.run(b.tree, b.coarse_rest.data(), xb.data(), b.coarse_rest.rows(), ratio, outb.data());
        EXPECT_TRUE(bitwise_equal(outa, a.tree.spheres)) << "levels " << levels << " frame " << frame;
        EXPECT_TRUE(bitwise_equal(outb, b.tree.spheres)) << "levels " << levels << " frame " << frame;
        // The spheres moved: the check compares a real update, not the rest state.
        EXPECT_FALSE(bitwise_equal(a.tree.spheres, a.tree.rest_spheres));

        collide(a.tree, b.tree, CollisionRequest{}, res);
        nlt.run(a.tree.spheres.data(), pa, b.tree.spheres.data(), pb);
        ASSERT_FALSE(res.interrupted);
        EXPECT_TRUE(res.untested.empty());
        EXPECT_EQ(nlt.tests, res.tests) << "levels " << levels << " frame " << frame;
        EXPECT_EQ(nlt.colliding, res.colliding) << "levels " << levels << " frame " << frame;
        // Brute force: the reported leaf pairs do overlap.
        for (const NodePair& p : nlt.colliding) {
          EXPECT_TRUE(a.tree.is_leaf(p.a) && b.tree.is_leaf(p.b));
          EXPECT_TRUE(overlap(a.tree.spheres[p.a], b.tree.spheres[p.b]));
        }
        total_pairs += static_cast<int64_t>(nlt.colliding.size());
      }
    }
    EXPECT_GT(total_pairs, 0) << "the objects must touch for the comparison to mean anything";
  }
}

}  // namespace
}  // namespace icd::collision::experiments
