#include <gtest/gtest.h>

#include <span>
#include <string>

#include "experiments/runner/run.hpp"
#include "experiments/runner/scene.hpp"
#include <icd/mesh/core/error.hpp>

namespace icd::runner {
namespace {

Scene parse(const std::string& text) {
  return parse_scene(parse_json(text, "s.json"), "s.json", ".");
}

const char* kSphere = R"({"name": "a", "primitive": {"type": "sphere"}})";

std::string with_objects(const std::string& objects, const std::string& extra = "") {
  return "{\"objects\": [" + objects + "]" + (extra.empty() ? "" : ", " + extra) + "}";
}

TEST(Scene, ParsesDefaultsAndFields) {
  const Scene s = parse(with_objects(
      R"({"name": "a", "primitive": {"type": "sphere", "radius": 0.2}, "velocity": [1, 0, 0],
          "material": {"model": "corotational", "young": 2e5, "poisson": 0.45, "density": 900,
                       "rayleigh": [0.1, 0.001]}, "integrator": "symplectic_euler"})",
      R"("frames": 7, "collision": {"budget_tests": 100, "mode": "priority"})"));
  ASSERT_EQ(s.objects.size(), 1u);
  const ObjectSpec& o = s.objects[0];
  EXPECT_EQ(s.frames, 7);
  EXPECT_DOUBLE_EQ(o.primitive->radius, 0.2);
  EXPECT_EQ(o.material.model, fem::MaterialModel::Corotational);
  EXPECT_DOUBLE_EQ(o.material.poisson, 0.45);
  EXPECT_DOUBLE_EQ(o.damping.beta, 0.001);
  EXPECT_EQ(o.integrator, fem::Integrator::SymplecticEuler);
  EXPECT_EQ(o.mass_scaling_target, coupling::ObjectSetup{}.mass_scaling_target);
  EXPECT_EQ(parse(with_objects(R"({"primitive": {}, "fem": {"mass_scaling_target": 0}})"))
                .objects[0]
                .mass_scaling_target,
            0.0);
  EXPECT_EQ(s.world.collision.query.budget_tests, 100);
  EXPECT_EQ(s.world.collision.query.mode, collision::TraversalMode::Priority);
  EXPECT_TRUE(std::isinf(s.world.collision.query.budget_seconds));  // a test budget alone
  EXPECT_FALSE(s.world.collision.query.parent_filter);
  EXPECT_TRUE(s.world.collision.layered);
  const Scene f = parse(with_objects(
      R"({"name": "a", "primitive": {"type": "sphere", "radius": 0.2}})",
      R"("collision": {"parent_filter": true, "layered": false})"));
  EXPECT_TRUE(f.world.collision.query.parent_filter);
  EXPECT_FALSE(f.world.collision.layered);
}

// One default per value: a field left out of the scene keeps the library's
// default (fem::Material, coupling::CollisionSpec).
TEST(Scene, FieldsLeftOutKeepTheLibraryDefaults) {
  const Scene s = parse(with_objects(
      R"({"name": "a", "primitive": {}, "material": {"poisson": 0.25}})", R"("collision": {})"));
  const fem::Material m;
  EXPECT_EQ(s.objects[0].material.young, m.young);
  EXPECT_EQ(s.objects[0].material.density, m.density);
  EXPECT_EQ(s.objects[0].material.model, m.model);
  EXPECT_EQ(s.objects[0].mass_scaling_target, coupling::ObjectSetup{}.mass_scaling_target);
  const coupling::CollisionSpec c;
  const collision::CollisionRequest& q = s.world.collision.query;
  EXPECT_EQ(q.budget_seconds, c.query.budget_seconds);
  EXPECT_EQ(q.budget_tests, c.query.budget_tests);
  EXPECT_EQ(q.mode, c.query.mode);
  EXPECT_EQ(q.clock_check_interval, c.query.clock_check_interval);
  EXPECT_EQ(q.depth_cap, c.query.depth_cap);
  EXPECT_EQ(q.max_list_size, c.query.max_list_size);
  EXPECT_EQ(s.world.collision.contact.stiffness, c.contact.stiffness);
  EXPECT_EQ(s.world.collision.update.mode, c.update.mode);
  EXPECT_EQ(s.world.frame_rate, coupling::WorldSettings{}.frame_rate);

  // The literal Fig. 7 mode is a traversal mode, with the paper's clock read at every test.
  const Scene lit = parse(with_objects(R"({"primitive": {}})", R"("collision": {"mode": "fifo_literal"})"));
  EXPECT_EQ(lit.world.collision.query.mode, collision::TraversalMode::BreadthFirstLiteral);
  EXPECT_EQ(lit.world.collision.query.clock_check_interval, 1);
}

// A scene text that must be refused, the field the message must name and what
// it must say.
struct BadField {
  std::string text;
  const char* field;
  const char* what;
};

// Each case gets an InputError naming the file ("s.json: "), the field and what is wrong.
void expect_each_rejected(std::span<const BadField> cases) {
  for (const auto& c : cases) {
    try {
      parse(c.text);
      ADD_FAILURE() << "accepted: " << c.text;
    } catch (const InputError& e) {
      const std::string msg = e.what();
      EXPECT_EQ(msg.rfind("s.json: ", 0), 0u) << msg;
      EXPECT_NE(msg.find(std::string(c.field) + ":"), std::string::npos) << msg;
      EXPECT_NE(msg.find(c.what), std::string::npos) << msg;
    }
  }
}

// Every bad field gets an InputError naming the file and the field.
TEST(Scene, EachBadFieldGetsAClearError) {
  const BadField cases[] = {
      {"{}", "objects", "non-empty array"},
      {with_objects(""), "objects", "non-empty array"},
      {with_objects(R"({"name": "a"})"), "objects[0]", "exactly one of"},
      {with_objects(R"({"mesh": "x.off", "primitive": {}})"), "objects[0]", "exactly one of"},
      {with_objects(R"({"primitive": {}, "material": {"poisson": 0.5}})"),
       "objects[0].material.poisson", "(-1, 0.5)"},
      {with_objects(R"({"primitive": {}, "material": {"young": -1}})"), "objects[0].material.young",
       "must be in"},
      {with_objects(R"({"primitive": {}, "material": {"density": 0}})"),
       "objects[0].material.density", "must be in"},
      {with_objects(R"({"primitive": {}, "material": {"rayleigh": [1]}})"),
       "objects[0].material.rayleigh", "[alpha, beta]"},
      {with_objects(R"({"primitive": {}, "integrator": "euler"})"), "objects[0].integrator",
       "must be one of"},
      {with_objects(R"({"primitive": {}})",
                    R"("collision": {"mode": "fifo_literal", "parent_filter": true})"),
       "collision.parent_filter", "no parent filter"},
      {with_objects(R"({"primitive": {}, "kind": "static", "velocity": [1, 0, 0]})"),
       "objects[0].velocity", "static"},
      {with_objects(R"({"primitive": {}, "initial_compression": 0.99})"),
       "objects[0].initial_compression", "must be in [0, 0.95]"},
      {with_objects(R"({"primitive": {}, "kind": "rigid", "initial_compression": 0.5})"),
       "objects[0].initial_compression", "deformable"},
      {with_objects(R"({"primitive": {}, "fem": {"mass_scaling_target": 1.5}})"),
       "objects[0].fem.mass_scaling_target", "must be in [0, 1]"},
      {with_objects(R"({"primitive": {}, "fem": {"mass_scaling": 0.5}})"),
       "objects[0].fem.mass_scaling", "unknown field"},
      {with_objects(R"({"primitive": {}, "velocity": [1, 0]})"), "objects[0].velocity",
       "array of 3"},
      {with_objects(R"({"primitive": {}, "fixed_nodes": [1, -2]})"), "objects[0].fixed_nodes[1]",
       "non-negative integer"},
      {with_objects(R"({"primitive": {"type": "cone"}})"), "objects[0].primitive.type",
       "must be one of"},
      {with_objects(R"({"primitive": {}, "colour": "red"})"), "objects[0].colour", "unknown field"},
      {with_objects(std::string(kSphere) + "," + kSphere), "objects[1].name", "duplicate"},
      {with_objects(kSphere, R"("frames": 0)"), "frames", "must be in"},
      {with_objects(kSphere, R"("frames": 2.5)"), "frames", "integer"},
      {with_objects(kSphere, R"("frame_rate": 0)"), "frame_rate", "must be in"},
      {with_objects(kSphere, R"("collision": {"budget_seconds": -1})"), "collision.budget_seconds",
       "must be in"},
      {with_objects(kSphere, R"("collision": {"budget_seconds": 0})"), "collision.budget_seconds",
       "must be in"},
      {with_objects(kSphere, R"("collision": {"budget_tests": -5})"), "collision.budget_tests",
       "must be in"},
      {with_objects(kSphere, R"("collision": {"stiffness": 0})"), "collision.stiffness",
       "must be in"},
      {with_objects(kSphere, R"("collision": {"mode": "random"})"), "collision.mode",
       "must be one of"},
      {with_objects(kSphere, R"("output": {"vtu_every": -1})"), "output.vtu_every", "must be in"},
      {with_objects(kSphere, R"("output": {"csv": "yes"})"), "output.csv", "true or false"},
  };
  expect_each_rejected(cases);
}

// Level of detail: collision.budget_split and each object's collision_weight
// reach the World's settings and objects, as do collision.cycles_at_fem_step
// and collision.predict_contact; left out, the library defaults.
TEST(Scene, BudgetSplitAndCollisionWeightReachTheWorld) {
  const Scene s = parse(with_objects(
      R"({"name": "a", "primitive": {"type": "sphere", "radius": 0.1, "cells": 3},
          "position": [-0.3, 0, 0], "collision_weight": 2.5},
         {"name": "b", "primitive": {"type": "sphere", "radius": 0.1, "cells": 3},
          "position": [0.3, 0, 0]})",
      R"("collision": {"budget_split": "priority", "cycles_at_fem_step": false,
          "predict_contact": false})"));
  EXPECT_EQ(s.world.collision.budget_split, coupling::BudgetSplit::Priority);
  // (both on by default: the keys turn them off)
  ASSERT_TRUE(coupling::CollisionSpec{}.cycles_at_fem_step);
  ASSERT_TRUE(coupling::CollisionSpec{}.predict_contact);
  EXPECT_FALSE(s.world.collision.cycles_at_fem_step);
  EXPECT_FALSE(s.world.collision.predict_contact);
  EXPECT_EQ(s.objects[0].collision_weight, 2.5);
  EXPECT_EQ(s.objects[1].collision_weight, coupling::ObjectSetup{}.collision_weight);
  const World world = make_world(s, "", "");
  EXPECT_EQ(world.settings().collision.budget_split, coupling::BudgetSplit::Priority);
  EXPECT_EQ(world.objects()[0].setup.collision_weight, 2.5);
  EXPECT_EQ(world.objects()[1].setup.collision_weight, 1.0);

  const Scene even = parse(with_objects(kSphere, R"("collision": {"budget_split": "even"})"));
  EXPECT_EQ(even.world.collision.budget_split, coupling::BudgetSplit::Even);
  const Scene cheap = parse(with_objects(kSphere, R"("collision": {"budget_split": "cheapest"})"));
  EXPECT_EQ(cheap.world.collision.budget_split, coupling::BudgetSplit::Cheapest);
  const Scene plain = parse(with_objects(kSphere));
  EXPECT_EQ(plain.world.collision.budget_split, coupling::CollisionSpec{}.budget_split);
  EXPECT_EQ(plain.world.collision.cycles_at_fem_step, coupling::CollisionSpec{}.cycles_at_fem_step);
  EXPECT_EQ(plain.world.collision.predict_contact, coupling::CollisionSpec{}.predict_contact);
  EXPECT_EQ(plain.objects[0].collision_weight, coupling::ObjectSetup{}.collision_weight);

  // Bad values: an InputError naming the file and the field.
  const BadField cases[] = {
      {with_objects(kSphere, R"("collision": {"budget_split": "random"})"),
       "collision.budget_split", "must be one of"},
      {with_objects(kSphere, R"("collision": {"budget_split": 1})"), "collision.budget_split",
       "string"},
      {with_objects(kSphere, R"("collision": {"cycles_at_fem_step": "yes"})"),
       "collision.cycles_at_fem_step", "true or false"},
      {with_objects(kSphere, R"("collision": {"predict_contact": 1})"),
       "collision.predict_contact", "true or false"},
      {with_objects(R"({"primitive": {}, "collision_weight": 0})"), "objects[0].collision_weight",
       "must be in (0"},
      {with_objects(R"({"primitive": {}, "collision_weight": -2})"), "objects[0].collision_weight",
       "must be in (0"},
      {with_objects(R"({"primitive": {}, "collision_weight": "near"})"),
       "objects[0].collision_weight", "must be a number"},
      {with_objects(R"({"primitive": {}, "collision_weight": 1e7})"), "objects[0].collision_weight",
       "must be in (0"},
  };
  expect_each_rejected(cases);
}

// --dry-run plans: each scene runs only the stages it needs.
// "initial_compression" (the stability study's 70 % cases): the object's
// coarse nodes start squeezed along x about their centroid, y and z as at
// rest; the other object is untouched.
TEST(Scene, InitialCompressionSqueezesTheCoarseNodesAlongX) {
  const Scene s = parse(with_objects(
      R"({"name": "a", "primitive": {"type": "sphere", "radius": 0.1, "cells": 3},
          "position": [-0.3, 0, 0], "initial_compression": 0.7},
         {"name": "b", "primitive": {"type": "sphere", "radius": 0.1, "cells": 3},
          "position": [0.3, 0, 0]})"));
  EXPECT_DOUBLE_EQ(s.objects[0].initial_compression, 0.7);
  EXPECT_EQ(s.objects[1].initial_compression, 0);
  World world = make_world(s, "", "");
  const RuntimeObject& a = world.objects()[0];
  const RuntimeObject& b = world.objects()[1];
  const Eigen::RowVector3d rest = a.rest.colwise().maxCoeff() - a.rest.colwise().minCoeff();
  const Eigen::RowVector3d now = a.positions.colwise().maxCoeff() - a.positions.colwise().minCoeff();
  EXPECT_NEAR(now.x(), 0.3 * rest.x(), 1e-12);
  EXPECT_NEAR(now.y(), rest.y(), 1e-12);
  EXPECT_NEAR(now.z(), rest.z(), 1e-12);
  EXPECT_NEAR(a.positions.col(0).mean(), a.rest.col(0).mean(), 1e-12);
  EXPECT_TRUE(a.sim->positions().isApprox(a.positions));
  EXPECT_TRUE(b.positions.isApprox(b.rest));
}

TEST(Plan, OneObjectSceneHasNoCollisionPipeline) {
  const Scene s = parse(with_objects(kSphere, R"("output": {"vtu_every": 0})"));
  const coupling::StagePlan p = scene_plan(s);
  EXPECT_TRUE(p.objects[0].fem);
  EXPECT_FALSE(p.objects[0].sphere_tree);
  EXPECT_FALSE(p.objects[0].sphere_update);
  EXPECT_FALSE(p.objects[0].dense_update);  // nothing consumes the dense mesh
  EXPECT_TRUE(p.pairs.empty());
  EXPECT_FALSE(p.response);
  const auto lines = describe_plan(s);
  EXPECT_EQ(lines[0], "a: load, fem (stvk, rk4)");
  EXPECT_EQ(lines[1], "collision: none");
}

TEST(Plan, RigidObstacleGetsNoFemButCollides) {
  const Scene s = parse(with_objects(
      R"({"name": "ball", "primitive": {}}, {"name": "wall", "primitive": {"type": "box"}, "kind": "static", "collider": "spheres"})",
      R"("output": {"vtu_every": 5})"));
  const coupling::StagePlan p = scene_plan(s);
  EXPECT_TRUE(p.objects[0].fem);
  EXPECT_FALSE(p.objects[1].fem);
  EXPECT_FALSE(p.objects[1].kinematic);
  EXPECT_TRUE(p.objects[1].sphere_tree);
  EXPECT_FALSE(p.objects[1].sphere_update);  // never moves
  EXPECT_FALSE(p.objects[1].dense_update);
  EXPECT_TRUE(p.objects[0].dense_update);  // written to VTU
  ASSERT_EQ(p.pairs.size(), 1u);
  EXPECT_TRUE(p.response);
  EXPECT_FALSE(p.broad_phase);
  const auto lines = describe_plan(s);
  EXPECT_EQ(lines[1], "wall: load, static, sphere tree");
}

// By default a static box collides as an analytic box obstacle, not through
// its sphere tree.
TEST(Plan, StaticBoxIsAnAnalyticObstacleByDefault) {
  const Scene s = parse(with_objects(
      R"({"name": "ball", "primitive": {}}, {"name": "wall", "primitive": {"type": "box"}, "kind": "static"})",
      R"("output": {"vtu_every": 5})"));
  const coupling::StagePlan p = scene_plan(s);
  EXPECT_TRUE(p.pairs.empty());
  EXPECT_FALSE(p.objects[1].sphere_tree);
  bool listed = false;
  for (const std::string& l : describe_plan(s)) listed = listed || l.rfind("obstacles: 1", 0) == 0;
  EXPECT_TRUE(listed);
}

TEST(Plan, TwoDeformableObjectsRunEverything) {
  const Scene s = parse(with_objects(
      R"({"name": "a", "primitive": {}}, {"name": "b", "primitive": {}, "integrator": "backward_euler"},
         {"name": "c", "primitive": {}, "kind": "rigid", "velocity": [0, 0, -1]})",
      R"("output": {"exact_reference": true})"));
  const coupling::StagePlan p = scene_plan(s);
  EXPECT_EQ(p.pairs.size(), 3u);
  EXPECT_TRUE(p.broad_phase);
  EXPECT_TRUE(p.objects[2].kinematic);
  EXPECT_TRUE(p.objects[2].sphere_update);
  for (const coupling::ObjectPlan& o : p.objects) EXPECT_TRUE(o.dense_update);  // exact reference needs them
  EXPECT_EQ(
      describe_plan(s)[1],
      "b: load, fem (stvk, backward_euler), sphere tree, sphere update, rigid links (dense mesh)");
}

}  // namespace
}  // namespace icd::runner
