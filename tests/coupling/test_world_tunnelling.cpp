// No tunnelling: objects that cross each other between two queries are
// still found (collision.swept), and a contact deeper than the spheres
// resolve is reported (FrameMetrics::deep_pairs), never silent.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string>
#include <vector>

#include <icd/coupling/primitive_asset.hpp>
#include <icd/coupling/world.hpp>

namespace icd::coupling {
namespace {

WorldObject ball(const std::string& name, const Eigen::Vector3d& at, const Eigen::Vector3d& v) {
  PrimitiveSpec p;
  p.radius = 0.1;
  p.subdivisions = 2;
  p.cells = 5;
  WorldObject o;
  o.setup.name = name;
  o.setup.material.model = fem::MaterialModel::StableNeoHookean;
  o.setup.material.young = 5e5;
  o.setup.velocity = v;
  o.asset = make_primitive_asset(p, 3);
  place_asset(o.asset, {0, at, {0, 0, 0}});
  return o;
}

WorldSettings settings(bool swept) {
  WorldSettings s;
  s.collision.query.budget_tests = 1000000;
  s.collision.query.budget_seconds = std::numeric_limits<double>::infinity();
  s.collision.contact.stiffness = 2000;
  s.collision.swept = swept;
  return s;
}

struct Outcome {
  double max_penetration = 0;
  int deep_frames = 0, max_cycles = 0, single_cycle_frames = 0;
};

// Two balls (radius 0.1 m, 4 cm apart) thrown head-on at +-speed.
Outcome head_on(double speed, bool swept, int frames) {
  std::vector<WorldObject> objects;
  objects.push_back(ball("left", {-0.12, 0, 0}, {speed, 0, 0}));
  objects.push_back(ball("right", {0.12, 0, 0}, {-speed, 0, 0}));
  World world(std::move(objects), settings(swept));
  Outcome out;
  for (int f = 0; f < frames; ++f) {
    const FrameMetrics m = world.step();
    out.max_penetration = std::max(out.max_penetration, m.max_penetration);
    out.deep_frames += m.deep_pairs > 0;
    out.max_cycles = std::max(out.max_cycles, m.cycles);
    out.single_cycle_frames += m.cycles == 1;
  }
  return out;
}

// At +-10 and +-50 m/s the balls cross each other within one 60 Hz frame:
// sampled at the end of the frame only, the contact is missed.
TEST(Tunnelling, EndOfFrameQueriesMissFastBalls) {
  EXPECT_EQ(head_on(10, false, 3).max_penetration, 0.0);
  EXPECT_EQ(head_on(50, false, 2).max_penetration, 0.0);
}

TEST(Tunnelling, SweptQueriesFindFastBallsAndReportDeepPenetration) {
  for (double speed : {10.0, 50.0}) {
    const Outcome o = head_on(speed, true, 3);
    EXPECT_GT(o.max_penetration, 0.0) << speed << " m/s";
    // A 2 kN/m penalty cannot stop 4 kg balls at these speeds: they pass
    // through each other, and the frames say so.
    EXPECT_GT(o.deep_frames, 0) << speed << " m/s";
    EXPECT_GT(o.max_cycles, 1) << speed << " m/s";
  }
}

TEST(Tunnelling, SlowBallsStillBounceWithoutDeepContact) {
  const Outcome o = head_on(0.6, true, 40);
  EXPECT_GT(o.max_penetration, 0.0);
  EXPECT_EQ(o.deep_frames, 0);
}

// Frames that are truly apart stay one cycle each, even at 50 m/s: two balls
// flying past each other 0.3 m apart.
TEST(Tunnelling, FastBallsFlyingPastEachOtherStayOneCyclePerFrame) {
  std::vector<WorldObject> objects;
  objects.push_back(ball("left", {-0.5, 0, 0}, {50, 0, 0}));
  objects.push_back(ball("right", {0.5, 0.5, 0}, {-50, 0, 0}));
  World world(std::move(objects), settings(true));
  for (int f = 0; f < 4; ++f) {
    const FrameMetrics m = world.step();
    EXPECT_EQ(m.cycles, 1) << "frame " << f;
    EXPECT_EQ(m.max_penetration, 0.0);
  }
}

// Issue 31, main-job contacts: two balls head-on at several speeds, each
// frame cycled, the response as configured. Energy (kinetic + elastic +
// penalty springs) at the start and once the balls are apart again, and
// the deepest leaf pair relative to its radius.
struct Bounce {
  double e0 = 0, e_after = -1, max_ratio = 0;
  int contact_frames = 0, deep_frames = 0, deep_steps = 0;
};

Bounce bounce(double speed, bool hold, int frames = 60) {
  WorldSettings s = settings(true);
  s.collision.node_rate_cap = hold;
  s.collision.deep_step_ratio = hold ? 0.5 : 0.0;
  std::vector<WorldObject> objects;
  objects.push_back(ball("left", {-0.105, 0, 0}, {speed, 0, 0}));
  objects.push_back(ball("right", {0.105, 0, 0}, {-speed, 0, 0}));
  World world(std::move(objects), s);
  Bounce b;
  for (const RuntimeObject& o : world.objects())  // kinetic at the start (no elastic energy)
    b.e0 += o.sim->model().kinetic_energy(o.sim->velocities());
  for (int f = 0; f < frames && b.e_after < 0; ++f) {
    const FrameMetrics m = world.step();
    b.max_ratio = std::max(b.max_ratio, m.depth_ratio);
    b.deep_frames += m.deep_pairs > 0;
    b.deep_steps += m.deep_steps;
    if (m.active_pairs > 0) ++b.contact_frames;
    if (b.contact_frames > 0 && m.active_pairs == 0 && b.e_after < 0) b.e_after = m.energy;
    if (std::getenv("ICD_TEST_VERBOSE"))
      std::printf("%.1f m/s frame %d energy %.5f ratio %.3f deep %d steps %d capped %lld cycles %d "
                  "softened %d\n",
                  speed, f, m.energy, m.depth_ratio, m.deep_pairs, m.deep_steps,
                  static_cast<long long>(m.capped_pairs), m.cycles, m.softened);
  }
  return b;
}

// With the node rate cap and the deep-contact velocity step (defaults) the
// balls, 1 cm apart, bounce at 0.6-5 m/s with no energy gain and no leaf pair
// deeper than 2 radii (1.2-1.6 at first contact, measured: the first sighting
// of a small leaf); without them the 5 m/s contact blows up (energy 1e13 J,
// the FEM health check throws) or goes deeper.
TEST(Tunnelling, HeadOnContactHoldsAndGainsNoEnergy) {
  for (double speed : {0.6, 2.0, 5.0}) {
    const Bounce b = bounce(speed, true);
    std::printf("%.1f m/s: energy %.4f -> %.4f J, deepest leaf pair %.2f radii, %d deep frames, "
                "%d velocity steps\n",
                speed, b.e0, b.e_after, b.max_ratio, b.deep_frames, b.deep_steps);
    EXPECT_GT(b.contact_frames, 0) << speed;
    ASSERT_GE(b.e_after, 0) << speed << " m/s: still in contact after 60 frames";
    EXPECT_LE(b.e_after, b.e0) << speed << " m/s";
    EXPECT_LT(b.max_ratio, 2.0) << speed << " m/s";
    EXPECT_GT(b.deep_steps, 0) << speed << " m/s";
  }
  bool failed = false;
  try {
    failed = bounce(5.0, false, 4).max_ratio >= 2.0;
  } catch (const std::exception& e) {
    failed = std::string(e.what()).find("health check") != std::string::npos;
  }
  EXPECT_TRUE(failed) << "without the cap and the step, the 5 m/s contact held";
}

}  // namespace
}  // namespace icd::coupling
