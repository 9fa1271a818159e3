// The near-limit loops of the collision benchmark (experiments/studies/
// collision/near_limit.hpp) must do exactly the library's work: the same
// spheres after the update (bitwise) and the same leaf pairs, in the same
// order, and the same number of sphere tests as collide()'s full traversal,
// on a few deformed frames of two overlapping objects.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include <icd/collision/node_association.hpp>
#include <icd/collision/octree_tree.hpp>
#include <icd/collision/sphere_update.hpp>
#include <icd/collision/traversal.hpp>
#include <icd/mesh/core/primitives.hpp>

#include "experiments/studies/collision/near_limit.hpp"

namespace icd::collision::experiments {
namespace {

struct Body {
  SurfaceMesh dense;
  MatX3d coarse_rest;
  SphereTree tree;
};

Body body(int levels, const Eigen::RowVector3d& shift) {
  Body o;
  o.dense = make_icosphere(3, 1.0);
  o.dense.V.rowwise() += shift;
  // Every 5th vertex stands in for a coarse node.
  o.coarse_rest.resize((o.dense.V.rows() + 4) / 5, 3);
  for (int i = 0; i < o.coarse_rest.rows(); ++i) o.coarse_rest.row(i) = o.dense.V.row(5 * i);
  OctreeTreeOptions opt;
  opt.levels = levels;
  o.tree = build_octree_tree(o.dense.V, o.dense.F, opt);
  NodeAssociationOptions ao;
  ao.k_nearest = 4;
  ao.max_nodes = 16;
  associate_nearest_nodes(o.tree, o.coarse_rest, ao);
  return o;
}

MatX3d deformed(const MatX3d& X, double t) {
  MatX3d x(X.rows(), 3);
  for (int i = 0; i < X.rows(); ++i) {
    x(i, 0) = X(i, 0) + 0.08 * std::sin(3 * X(i, 1) + t);
    x(i, 1) = X(i, 1) + 0.08 * std::sin(2 * X(i, 2) + 1.3 * t);
    x(i, 2) = X(i, 2) + 0.08 * std::sin(2.5 * X(i, 0) + 0.7 * t);
  }
  return x;
}

bool bitwise_equal(const std::vector<Sphere>& x, const std::vector<Sphere>& y) {
  return x.size() == y.size() && std::memcmp(x.data(), y.data(), x.size() * sizeof(Sphere)) == 0;
}

TEST(CollisionStudies, NearLimitLoopsMatchTheLibrary) {
  for (int levels : {3, 5}) {
    Body a = body(levels, {0, 0, 0}), b = body(levels, {1.3, 0.4, 0.1});
    const PackedTree pa(a.tree), pb(b.tree);
    NearLimitUpdate nlu;
    NearLimitTraversal nlt;
    CollisionResult res;
    std::vector<Sphere> outa(a.tree.spheres.size()), outb(b.tree.spheres.size());
    int64_t total_pairs = 0;
    for (int frame = 0; frame < 4; ++frame) {
      const MatX3d xa = deformed(a.coarse_rest, 0.4 * frame),
                   xb = deformed(b.coarse_rest, 0.4 * frame + 1.0);
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
