// No tunnelling: objects that cross each other between two queries are
// still found (collision.swept), and a contact deeper than the spheres
// resolve is reported (FrameMetrics::deep_pairs), never silent.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
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

}  // namespace
}  // namespace icd::coupling
