// Scheduling of the frame between objects and pairs: objects in no close
// pair skip the cycles others' contacts need (plan_islands), and one query
// budget shared among pairs by priority (collision.budget_split).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <icd/coupling/primitive_asset.hpp>
#include <icd/coupling/world.hpp>
#include <icd/mesh/core/error.hpp>

namespace icd::coupling {
namespace {

WorldObject ball(const std::string& name, const Eigen::Vector3d& x, const Eigen::Vector3d& v,
                 double radius = 0.1) {
  PrimitiveSpec p;
  p.radius = radius;
  p.subdivisions = 2;
  p.cells = 5;
  WorldObject o;
  o.setup.name = name;
  o.setup.material.young = 5e5;
  o.setup.velocity = v;
  o.asset = make_primitive_asset(p, 3);
  place_asset(o.asset, {0, x, {0, 0, 0}});
  return o;
}

WorldSettings deterministic() {
  WorldSettings s;
  s.collision.query.budget_tests = 1000000;
  s.collision.query.budget_seconds = std::numeric_limits<double>::infinity();
  s.collision.contact.stiffness = 2000;
  s.threads = 1;
  return s;
}

/// A scripted (kinematic) ball held at x: its spheres are the same in every
/// world whatever the budget (the level-of-detail tests).
WorldObject still_ball(const std::string& name, const Eigen::Vector3d& x) {
  WorldObject o = ball(name, x, {0, 0, 0});
  o.setup.kind = ObjectKind::Rigid;
  o.setup.motion = [](double) { return RigidPose{}; };  // rest = placed pose
  return o;
}

/// deterministic() with an unlimited query budget: the level-of-detail oracle.
WorldSettings unlimited() {
  WorldSettings s = deterministic();
  s.collision.query.budget_tests = -1;
  return s;
}

/// Balls "left" and "right" at x = -x0 and x0, heading for each other at `speed`.
std::vector<WorldObject> head_on_pair(double x0, double speed) {
  std::vector<WorldObject> v;
  v.push_back(ball("left", {-x0, 0, 0}, {speed, 0, 0}));
  v.push_back(ball("right", {x0, 0, 0}, {-speed, 0, 0}));
  return v;
}

const RuntimeObject& named(const World& w, const std::string& name) {
  for (const RuntimeObject& o : w.objects())
    if (o.setup.name == name) return o;
  throw std::runtime_error("no object " + name);
}

// A head-on pair runs many cycles per frame while in contact; a third ball,
// far from both, is in no close pair: it must advance exactly as it does
// in a world where nothing is in contact (one advance over each frame),
// bitwise, instead of being cut into the pair's cycles.
TEST(WorldScheduling, FarObjectDoesNotPayForTheCyclesOfAContact) {
  std::vector<WorldObject> busy;
  busy.push_back(ball("left", {-0.12, 0, 0}, {0.6, 0, 0}));
  busy.push_back(ball("right", {0.12, 0, 0}, {-0.6, 0, 0}));
  busy.push_back(ball("far", {3, 0, 0}, {0, 0.2, 0}));
  // Reference: the same far ball, with a partner that never comes near it.
  std::vector<WorldObject> quiet;
  quiet.push_back(ball("decoy", {-3, 0, 0}, {0, -0.2, 0}));
  quiet.push_back(ball("far", {3, 0, 0}, {0, 0.2, 0}));
  World world(std::move(busy), deterministic());
  World reference(std::move(quiet), deterministic());
  int cycled_frames = 0;
  for (int f = 0; f < 30; ++f) {
    const FrameMetrics m = world.step();
    const FrameMetrics r = reference.step();
    ASSERT_EQ(r.cycles, 1) << "frame " << f;  // nothing near anything
    const RuntimeObject& far = named(world, "far");
    const RuntimeObject& ref = named(reference, "far");
    if (m.cycles > ref.substeps) ++cycled_frames;  // old path: >= 1 sub-step per cycle
    // (a frame tried as one cycle and rolled back counts the trial's work too)
    ASSERT_EQ(far.substeps, ref.substeps * (1 + m.rollback))
        << "frame " << f << ", " << m.cycles << " cycles";
    ASSERT_TRUE((far.positions.array() == ref.positions.array()).all()) << "frame " << f;
    ASSERT_TRUE((far.sim->velocities().array() == ref.sim->velocities().array()).all())
        << "frame " << f;
  }
  // The pair did go through a contact that cut its frames into more cycles
  // than the far ball's sub-steps.
  EXPECT_GT(cycled_frames, 0);
}

// A contact's response depends on the objects in contact only: adding a
// resting object with much lighter coarse nodes (a finer mesh), far from the
// pair, changes neither the pair's cycles nor its softening, so the pair
// moves bitwise as without it. (Before: the cycle count and the softening
// used the lightest node of all objects, and the light far object cut the
// pair's frames into more cycles and softened its penalty.)
TEST(WorldScheduling, ALightObjectFarAwayDoesNotChangeAContact) {
  std::vector<WorldObject> with_light = head_on_pair(0.12, 0.6);
  PrimitiveSpec fine;
  fine.radius = 0.05;
  fine.subdivisions = 2;
  fine.cells = 9;
  WorldObject light;
  light.setup.name = "light";
  light.setup.material.young = 5e5;
  light.asset = make_primitive_asset(fine, 3);
  place_asset(light.asset, {0, {0, 3, 0}, {0, 0, 0}});
  with_light.push_back(std::move(light));
  World alone(head_on_pair(0.12, 0.6), deterministic());
  World crowd(std::move(with_light), deterministic());
  // The light object's nodes are lighter than the pair's (else this tests nothing).
  ASSERT_LT(crowd.objects()[2].node_mass.minCoeff(), 0.5 * alone.objects()[0].node_mass.minCoeff());
  int contact_frames = 0;
  for (int f = 0; f < 30; ++f) {
    const FrameMetrics a = alone.step();
    const FrameMetrics c = crowd.step();
    contact_frames += a.active_pairs > 0;
    ASSERT_EQ(a.cycles, c.cycles) << "frame " << f;
    ASSERT_EQ(a.softened, c.softened) << "frame " << f;
    for (int i = 0; i < 2; ++i) {
      ASSERT_TRUE((alone.objects()[i].positions.array() == crowd.objects()[i].positions.array()).all())
          << "frame " << f << " object " << i;
    }
  }
  EXPECT_GT(contact_frames, 0);
}

// Level of detail for many pairs. Scripted (kinematic) balls hold still, so
// every world sees the same spheres whatever its budget: three resting pairs
// just touching and one critical pair deeply overlapping. Oracle: the same
// scene with an unlimited budget. With a test budget too small for the
// critical pair's traversal, the even split (every pair the same budget)
// leaves it interrupted; the priority split gives it the share of its depth
// and finds exactly the oracle's colliding leaf pairs.
TEST(WorldScheduling, PrioritySplitFindsTheCriticalPairWhereTheEvenSplitDoesNot) {
  const auto scene = [] {
    std::vector<WorldObject> v;
    const auto still = [&v](const std::string& name, const Eigen::Vector3d& x) {
      v.push_back(still_ball(name, x));
    };
    for (int k = 0; k < 3; ++k) {  // resting pairs: 2 mm overlap
      still("rest" + std::to_string(k) + "a", {-0.1 + 0.001, 1.0 * k, 0});
      still("rest" + std::to_string(k) + "b", {0.1 - 0.001, 1.0 * k, 0});
    }
    still("deep_a", {-0.07, 3, 0});  // critical pair: 6 cm overlap
    still("deep_b", {0.07, 3, 0});
    v.push_back(ball("soft", {0, -5, 0}, {0, 0, 0}));  // a deformable object: response on
    return v;
  };
  World oracle(scene(), unlimited());
  oracle.step();
  oracle.step();
  // The pairs of the plan: find the critical and the resting ones.
  const auto& pairs = oracle.plan().pairs;
  const auto pair_of = [&](const World& w, const std::string& a, const std::string& b) {
    for (size_t p = 0; p < pairs.size(); ++p) {
      const std::string& na = w.objects()[pairs[p].first].setup.name;
      const std::string& nb = w.objects()[pairs[p].second].setup.name;
      if ((na == a && nb == b) || (na == b && nb == a)) return p;
    }
    throw std::runtime_error("no pair " + a + " - " + b);
  };
  const size_t critical = pair_of(oracle, "deep_a", "deep_b");
  const collision::CollisionResult& truth = oracle.results()[critical];
  ASSERT_FALSE(truth.interrupted);
  ASSERT_FALSE(truth.colliding.empty());
  for (int k = 0; k < 3; ++k) {
    const std::string r = "rest" + std::to_string(k);
    ASSERT_FALSE(oracle.results()[pair_of(oracle, r + "a", r + "b")].colliding.empty());
  }
  // A budget per query 70% of what the critical traversal needs.
  const int64_t budget = truth.tests * 7 / 10;
  auto sorted = [](std::vector<collision::NodePair> v) {
    std::sort(v.begin(), v.end(), [](const collision::NodePair& x, const collision::NodePair& y) {
      return std::pair(x.a, x.b) < std::pair(y.a, y.b);
    });
    return v;
  };
  const auto run = [&](BudgetSplit split) {
    WorldSettings s = deterministic();
    s.collision.query.budget_tests = budget;
    s.collision.budget_split = split;
    auto w = std::make_unique<World>(scene(), s);
    w->step();
    w->step();
    return w;
  };
  const std::unique_ptr<World> even = run(BudgetSplit::Even);
  const std::unique_ptr<World> priority = run(BudgetSplit::Priority);
  // Even: every queried pair the same budget; the critical query is cut short.
  EXPECT_EQ(even->pair_test_budgets()[critical], budget);
  EXPECT_TRUE(even->results()[critical].interrupted);
  EXPECT_NE(sorted(even->results()[critical].colliding), sorted(truth.colliding));
  // Priority: the queries of the last cycle used no more than the same
  // total (4 pairs x the budget), the critical pair got more than its even share.
  int64_t used = 0, queried = 0;
  for (size_t p = 0; p < pairs.size(); ++p)
    if (priority->pair_test_budgets()[p] > 0) {
      used += priority->results()[p].tests;
      ++queried;
    }
  EXPECT_EQ(queried, 4);
  EXPECT_LE(used, queried * budget);
  EXPECT_GT(priority->pair_test_budgets()[critical], budget);
  EXPECT_FALSE(priority->results()[critical].interrupted);
  EXPECT_EQ(sorted(priority->results()[critical].colliding), sorted(truth.colliding));
  // The resting pairs keep a budget of their own.
  for (int k = 0; k < 3; ++k) {
    const std::string r = "rest" + std::to_string(k);
    EXPECT_GT(priority->pair_test_budgets()[pair_of(*priority, r + "a", r + "b")], 0);
  }
}

// Level of detail by cost (BudgetSplit::Cheapest). Three still pairs
// (scripted balls) overlapping 2 mm, 2 cm and 6 cm, whose complete queries
// cost c1 < c2 < c3 tests (oracle: an unlimited query of the same scene, its
// answers checked against every leaf pair by brute force). A budget per query
// B with 3 B enough for the two cheapest complete answers but not the third,
// and B < c2: the even split completes at most one pair, the cheapest-first
// split two (after learning the costs: at first none is known),
// each exactly the brute-force answer; in every cycle the queries together
// use at most 3 B tests.
TEST(WorldScheduling, CheapestSplitAnswersAsManyPairsExactlyAsThePoolPaysFor) {
  const double overlap[3] = {0.002, 0.02, 0.06};
  const auto scene = [&] {
    std::vector<WorldObject> v;
    const auto still = [&v](const std::string& name, const Eigen::Vector3d& x) {
      v.push_back(still_ball(name, x));
    };
    for (int k = 0; k < 3; ++k) {
      still("p" + std::to_string(k) + "a", {-0.1 + overlap[k] / 2, 1.0 * k, 0});
      still("p" + std::to_string(k) + "b", {0.1 - overlap[k] / 2, 1.0 * k, 0});
    }
    v.push_back(ball("soft", {0, -5, 0}, {0, 0, 0}));  // a deformable object: response on
    return v;
  };
  World oracle(scene(), unlimited());
  oracle.step();
  const auto& pairs = oracle.plan().pairs;
  const auto pair_of = [&](int k) {
    const std::string a = "p" + std::to_string(k) + "a", b = "p" + std::to_string(k) + "b";
    for (size_t p = 0; p < pairs.size(); ++p)
      if (oracle.objects()[pairs[p].first].setup.name == a &&
          oracle.objects()[pairs[p].second].setup.name == b)
        return p;
    throw std::runtime_error("no pair " + a + " - " + b);
  };
  auto sorted = [](std::vector<collision::NodePair> v) {
    std::sort(v.begin(), v.end(), [](const collision::NodePair& x, const collision::NodePair& y) {
      return std::pair(x.a, x.b) < std::pair(y.a, y.b);
    });
    return v;
  };
  // Brute force: every overlapping leaf pair of the pair's current spheres.
  const auto brute = [&](const World& w, size_t p) {
    const collision::SphereTree& ta = w.objects()[pairs[p].first].asset.spheres;
    const collision::SphereTree& tb = w.objects()[pairs[p].second].asset.spheres;
    std::vector<collision::NodePair> out;
    for (int i = 0; i < ta.num_nodes(); ++i)
      for (int j = 0; j < tb.num_nodes(); ++j)
        if (ta.is_leaf(i) && tb.is_leaf(j) && collision::overlap(ta.spheres[i], tb.spheres[j]))
          out.push_back({i, j});
    return sorted(out);
  };
  int64_t cost[3];
  for (int k = 0; k < 3; ++k) {
    const collision::CollisionResult& truth = oracle.results()[pair_of(k)];
    ASSERT_FALSE(truth.interrupted);
    ASSERT_EQ(sorted(truth.colliding), brute(oracle, pair_of(k))) << "pair " << k;
    ASSERT_FALSE(truth.colliding.empty());
    cost[k] = truth.tests;
  }
  std::printf("complete costs %lld %lld %lld tests\n", static_cast<long long>(cost[0]),
              static_cast<long long>(cost[1]), static_cast<long long>(cost[2]));
  ASSERT_LT(cost[0], cost[1]);
  ASSERT_LT(cost[1], cost[2]);
  // 3 B pays for the two cheapest complete answers (and one test for the
  // third), not for all three; one pair alone cannot take c2 from B.
  const int64_t budget = (cost[0] + cost[1] + 1 + 2) / 3 + 1;
  ASSERT_LT(budget, cost[1]);
  ASSERT_LT(3 * budget, cost[0] + cost[1] + cost[2]);
  const auto run = [&](BudgetSplit split, int& cycles_over) {
    WorldSettings s = deterministic();
    s.collision.query.budget_tests = budget;
    s.collision.budget_split = split;
    auto w = std::make_unique<World>(scene(), s);
    w->set_cycle_observer([&](const World& world) {
      int64_t used = 0, queried = 0;
      for (size_t p = 0; p < pairs.size(); ++p)
        if (world.pair_test_budgets()[p] > 0) {
          used += world.results()[p].tests;
          ++queried;
        }
      cycles_over += used > queried * budget;
    });
    for (int f = 0; f < 3; ++f) w->step();
    return w;
  };
  int over_even = 0, over_cheapest = 0;
  const std::unique_ptr<World> even = run(BudgetSplit::Even, over_even);
  const std::unique_ptr<World> cheapest = run(BudgetSplit::Cheapest, over_cheapest);
  EXPECT_EQ(over_even, 0);
  EXPECT_EQ(over_cheapest, 0);
  // Even: at most the cheapest pair fits in B.
  EXPECT_EQ(even->results()[pair_of(0)].interrupted, cost[0] > budget);
  EXPECT_TRUE(even->results()[pair_of(1)].interrupted);
  EXPECT_TRUE(even->results()[pair_of(2)].interrupted);
  // Cheapest first: the two cheapest answered exactly, the third cut.
  for (int k = 0; k < 2; ++k) {
    const collision::CollisionResult& r = cheapest->results()[pair_of(k)];
    EXPECT_FALSE(r.interrupted) << "pair " << k;
    EXPECT_EQ(sorted(r.colliding), brute(*cheapest, pair_of(k))) << "pair " << k;
  }
  EXPECT_TRUE(cheapest->results()[pair_of(2)].interrupted);
  EXPECT_GT(cheapest->pair_test_budgets()[pair_of(2)], 0);
}

// Cycles fitted to the objects' sub-steps. Each cycle advances an object in
// ceil(h / step) equal sub-steps: 64 cycles of a 60 Hz frame (0.260 ms) cost
// an object whose sub-step is 0.256 ms two sub-steps each. Worked by hand:
// 16.667 ms / (0.256 ms x 0.97) = 67.1, so 68 cycles of one sub-step each.
TEST(WorldScheduling, CyclesAreFittedToTheSubStepsOfTheObjects) {
  const double dt = 1.0 / 60;
  EXPECT_EQ(World::fit_cycles(dt, 64, {{1, 0.256e-3}}), 68);
  // Never fewer cycles than needed (the penalty's stability), never more than 1.5 n + 2.
  EXPECT_EQ(World::fit_cycles(dt, 1, {{1, 0.256e-3}}), 1);  // one long cycle: no waste
  EXPECT_EQ(World::fit_cycles(dt, 64, {}), 64);            // nothing to fit
  EXPECT_EQ(World::fit_cycles(dt, 64, {{1, 0}}), 64);      // a step not known yet
  // Brute force over required counts and two objects of unequal steps: the
  // chosen count is within [n, 1.5 n + 2] and costs no more FEM sub-steps
  // (counted as the Simulator takes them, at kStepMargin below each step)
  // than the required one.
  const auto substeps = [&](int c, double step) {
    return c * static_cast<int>(std::ceil(dt / c / (step * (1 - World::kStepMargin)) - 1e-9));
  };
  for (int n = 1; n <= 200; ++n)
    for (const double s2 : {0.11e-3, 0.173e-3, 0.4e-3}) {
      const double s1 = 0.256e-3;
      const int c = World::fit_cycles(dt, n, {{1500, s1}, {700, s2}});
      ASSERT_GE(c, n);
      ASSERT_LE(c, n + n / 2 + 2);
      EXPECT_LE(1500 * substeps(c, s1) + 700 * substeps(c, s2),
                1500 * substeps(n, s1) + 700 * substeps(n, s2))
          << "n " << n << " s2 " << s2 << " chose " << c;
    }
}

TEST(WorldScheduling, RefusesANonPositiveCollisionWeight) {
  std::vector<WorldObject> v;
  v.push_back(ball("a", {-1, 0, 0}, {0, 0, 0}));
  v.push_back(ball("b", {1, 0, 0}, {0, 0, 0}));
  v[1].setup.collision_weight = 0;
  try {
    World w(std::move(v), deterministic());
    FAIL() << "accepted collision_weight 0";
  } catch (const ParameterError& e) {
    EXPECT_NE(std::string(e.what()).find("\"b\""), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("collision_weight"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace icd::coupling

namespace icd::coupling {
namespace {

struct ContactRun {
  int contact_frames = 0;
  int apart_substeps = 0;  ///< sub-steps of one ball in a frame apart (one contact-free cycle)
  int contact_substeps = 0;  ///< sub-steps of both balls summed over the contact frames
  int slow_frames = 0;       ///< contact frames whose motion bound is small (see below)
  int most_slow_penalty = 0;  ///< most penalty cycles of those frames
  int most_penalty_cycles = 0;
  double lightest = 0;  ///< lightest coarse node, kg
};

// Two balls head-on at 0.2 m/s, 1 cm apart (a slow contact, see
// World::contact_cycles): the frames in contact, with the cycle rule given.
ContactRun head_on_contact(bool cycles_at_fem_step) {
  WorldSettings s = deterministic();
  s.collision.cycles_at_fem_step = cycles_at_fem_step;
  World w(head_on_pair(0.105, 0.2), s);
  ContactRun r;
  r.lightest = std::min(w.objects()[0].node_mass.minCoeff(), w.objects()[1].node_mass.minCoeff());
  std::vector<FrameMetrics> contact;
  for (int f = 0; f < 20; ++f) {
    const FrameMetrics m = w.step();
    if (std::getenv("ICD_TEST_VERBOSE"))
      std::printf("frame %d cycles %d penalty %d motion %d substeps %d active %d rollback %d\n", f,
                  m.cycles, m.cycles_penalty, m.cycles_motion, m.substeps, m.active_pairs, m.rollback);
    // (the first frame run as one contact-free cycle: the balls start 1 cm
    // apart, frame 0 may already be a rolled-back trial)
    if (m.cycles == 1 && m.rollback == 0 && m.active_pairs == 0 && r.apart_substeps == 0)
      r.apart_substeps = w.objects()[0].substeps;
    if (m.active_pairs > 0) contact.push_back(m);
  }
  for (const FrameMetrics& m : contact) {
    ++r.contact_frames;
    r.contact_substeps += m.substeps;
    r.most_penalty_cycles = std::max(r.most_penalty_cycles, m.cycles_penalty);
    // Slow: the pair closes at most cycle_motion / 3 leaf radii per cycle
    // at one cycle per sub-step (the condition of the rule).
    if (3 * m.cycles_motion <= r.apart_substeps) {
      ++r.slow_frames;
      r.most_slow_penalty = std::max(r.most_slow_penalty, m.cycles_penalty);
    }
  }
  return r;
}

// With the per-node rate cap, a slow contact is cut into cycles as long as
// the objects' FEM sub-step: no more cycles than the sub-steps a ball takes
// over a frame apart (one cycle, its own step; +3 % for the cycle fitted
// kStepMargin below the step, and one for rounding), where the previous rule,
// omega h <= 0.25 for the full stiffness on the lightest node, asks for
// sqrt(k / m) dt / 0.25 cycles (worked out here from the node masses, at most
// 64), here more than the sub-steps: the rule now takes the fewer of the two,
// and the contact frames cost fewer sub-steps. (That contacts still hold
// without energy gain or deep pairs: Tunnelling.HeadOnContactHoldsAndGainsNoEnergy.)
TEST(WorldScheduling, SlowContactCyclesAreAsLongAsTheFemStepWithTheRateCap) {
  const ContactRun now = head_on_contact(true);
  const ContactRun before = head_on_contact(false);
  ASSERT_GT(now.contact_frames, 2);
  ASSERT_GT(before.contact_frames, 2);
  ASSERT_GT(now.apart_substeps, 4);
  // Previous rule, by hand from the lightest node and k = 2000 N/m.
  const double dt = 1.0 / 60;
  const int expected = std::min(64, static_cast<int>(std::ceil(std::sqrt(2000 / before.lightest) * dt / 0.25)));
  EXPECT_GE(before.most_penalty_cycles, expected);  // (the node stiffness may exceed k)
  ASSERT_GT(expected, now.apart_substeps + 2);  // (else the two rules agree here)
  ASSERT_GE(now.slow_frames, 2);
  EXPECT_LE(now.most_slow_penalty, static_cast<int>(std::ceil(1.04 * now.apart_substeps)) + 1);
  EXPECT_LT(now.contact_substeps, before.contact_substeps);
}

// A frame that starts apart and ends in contact used to run as one cycle,
// be rolled back and re-run in cycles (the single-cycle trial): the trial's
// sub-steps were paid for nothing. With the contact predicted from the node
// velocities (World::contact_ahead) that frame is cycled at once: no
// rollback, fewer sub-steps in it, the frames before it still one cycle
// each, and the same bounce as the trial path (cycle counts may differ, so
// not bitwise: exit velocity within 2 %, deepest contact within 10 %).
TEST(WorldScheduling, PredictedFirstContactSkipsTheRolledBackTrial) {
  struct Run {
    int rollbacks = 0, predicted = 0, contact_frames = 0, cycled_before = 0;
    int entry_substeps = 0;  // sub-steps of the frame that entered the contact
    double depth = 0, vx = 0;
  };
  const auto run = [](bool predict) {
    WorldSettings s = deterministic();
    s.collision.predict_contact = predict;
    World w(head_on_pair(0.15, 0.6), s);
    Run r;
    bool entered = false;
    for (int f = 0; f < 40; ++f) {
      const FrameMetrics m = w.step();
      if (!entered && (m.rollback || m.predicted)) {
        entered = true;
        r.entry_substeps = m.substeps;
      }
      if (!entered && m.cycles > 1) ++r.cycled_before;
      r.rollbacks += m.rollback;
      r.predicted += m.predicted;
      r.contact_frames += m.active_pairs > 0;
      r.depth = std::max(r.depth, m.max_penetration);
    }
    const RuntimeObject& left = w.objects()[0];
    const Eigen::VectorXd& mass = left.sim->model().mass();
    r.vx = (left.sim->velocities().transpose() * mass).x() / mass.sum();
    return r;
  };
  const Run trial = run(false), ahead = run(true);
  ASSERT_GT(trial.contact_frames, 2);
  EXPECT_GE(trial.rollbacks, 1);
  EXPECT_EQ(trial.predicted, 0);
  EXPECT_GE(ahead.predicted, 1);
  EXPECT_EQ(ahead.rollbacks, 0);
  EXPECT_EQ(ahead.cycled_before, 0);  // frames apart: one cycle each
  EXPECT_EQ(trial.cycled_before, 0);
  EXPECT_LT(ahead.entry_substeps, trial.entry_substeps);
  EXPECT_LT(trial.vx, -0.3);  // bounced back
  EXPECT_NEAR(ahead.vx, trial.vx, 0.02 * std::abs(trial.vx));
  EXPECT_NEAR(ahead.depth, trial.depth, 0.1 * trial.depth);
  EXPECT_NEAR(ahead.contact_frames, trial.contact_frames, 1);
}

// The pool hands every index to exactly one thread, job after job, whether
// its workers spin between jobs or block at once (the World's hand-off,
// thousands of times per second).
TEST(WorkerPool, RunsEveryIndexOnceWhetherWorkersSpinOrBlock) {
  for (const double spin : {0.0, 100e-6}) {
    WorkerPool pool(3, spin);
    ASSERT_EQ(pool.threads(), 3);
    for (int job = 0; job < 2000; ++job) {
      const int n = 1 + job % 5;
      std::vector<int> hits(static_cast<size_t>(n), 0);
      pool.run(n, [&](int k) { ++hits[static_cast<size_t>(k)]; });
      for (int k = 0; k < n; ++k) ASSERT_EQ(hits[static_cast<size_t>(k)], 1) << "job " << job << " index " << k;
    }
  }
  EXPECT_THROW(WorkerPool(2, -1e-6), ParameterError);
  EXPECT_THROW(WorkerPool(0), ParameterError);
}

}  // namespace
}  // namespace icd::coupling
