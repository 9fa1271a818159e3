#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>

#include <Eigen/Dense>

#include <icd/coupling/contact_response.hpp>
#include <icd/mesh/core/error.hpp>

namespace icd::coupling {
namespace {

using collision::CollisionResult;
using collision::NodePair;
using collision::Sphere;
using collision::SphereTree;

// A two-level tree: root + `n` leaves, sphere i tied to nodes given by `assoc`.
SphereTree make_tree(const std::vector<Sphere>& leaves, const std::vector<std::vector<int>>& assoc,
                     const Sphere& root = {0, 0, 0, 10}) {
  SphereTree t;
  t.spheres.push_back(root);
  for (const Sphere& s : leaves) t.spheres.push_back(s);
  std::vector<int32_t> parent(t.spheres.size(), 0);
  parent[0] = -1;
  collision::build_topology(t, parent);
  t.assoc_offset.push_back(0);
  for (const auto& nodes : assoc) {
    for (int n : nodes) {
      t.assoc_nodes.push_back(n);
      t.assoc_rest_dist.push_back(1.0);
    }
    t.assoc_offset.push_back(static_cast<int32_t>(t.assoc_nodes.size()));
  }
  return t;
}

TEST(ContactResponse, SinglePairFollowsEquation11) {
  // Spheres of radius 1 at distance 1.5 along (1, 2, 2)/3: penetration 0.5.
  const Eigen::Vector3d dir = Eigen::Vector3d(1, 2, 2) / 3.0;
  const Eigen::Vector3d cb = 1.5 * dir;
  const SphereTree a = make_tree({{0, 0, 0, 1}}, {{0}, {0}});
  const SphereTree b = make_tree({{cb.x(), cb.y(), cb.z(), 1}}, {{0}, {0}});
  CollisionResult r;
  r.colliding.push_back({1, 1});
  MatX3d fa = MatX3d::Zero(1, 3), fb = MatX3d::Zero(1, 3);
  ContactOptions o;
  o.stiffness = 200.0;
  const ContactStats s = apply_contact_forces(a, b, r, o, fa, fb);
  EXPECT_EQ(s.active_pairs, 1);
  EXPECT_NEAR(s.max_penetration, 0.5, 1e-15);
  EXPECT_LT((fb.row(0).transpose() - 100.0 * dir).norm(), 1e-12);
  EXPECT_LT((fa.row(0).transpose() + 100.0 * dir).norm(), 1e-12);
}

// The untested-pair cap: an untested pair (the roots, radii 10 and 10 at
// distance 1.5: penetration 18.5) pushes with k * cap; a colliding leaf pair is never
// capped; the penalty energy follows k delta^2 / 2 with the capped delta.
TEST(ContactResponse, UntestedPenetrationCapAppliesToUntestedPairsOnly) {
  const Eigen::Vector3d dir = Eigen::Vector3d(1, 2, 2) / 3.0;
  const Eigen::Vector3d cb = 1.5 * dir;
  const SphereTree a = make_tree({{0, 0, 0, 1}}, {{0}, {0}});
  const SphereTree b =
      make_tree({{cb.x(), cb.y(), cb.z(), 1}}, {{0}, {0}}, {cb.x(), cb.y(), cb.z(), 10});
  ContactOptions o;
  o.stiffness = 200.0;
  o.max_untested_penetration = 0.25;
  MatX3d fa = MatX3d::Zero(1, 3), fb = MatX3d::Zero(1, 3);
  CollisionResult untested;
  untested.untested.push_back({0, 0});
  ContactStats s = apply_contact_forces(a, b, untested, o, fa, fb);
  EXPECT_NEAR(s.max_penetration, 0.25, 1e-15);
  EXPECT_LT((fb.row(0).transpose() - 200.0 * 0.25 * dir).norm(), 1e-12);
  EXPECT_NEAR(s.penalty_energy, 0.5 * 200.0 * 0.25 * 0.25, 1e-12);
  o.max_untested_penetration = std::numeric_limits<double>::infinity();
  fa.setZero();
  fb.setZero();
  s = apply_contact_forces(a, b, untested, o, fa, fb);
  EXPECT_NEAR(s.max_penetration, 18.5, 1e-12);
  // A colliding leaf pair is not capped.
  o.max_untested_penetration = 0.25;
  CollisionResult colliding;
  colliding.colliding.push_back({1, 1});
  fa.setZero();
  fb.setZero();
  s = apply_contact_forces(a, b, colliding, o, fa, fb);
  EXPECT_NEAR(s.max_penetration, 0.5, 1e-15);
  o.max_untested_penetration = 0;
  EXPECT_THROW(apply_contact_forces(a, b, colliding, o, fa, fb), ParameterError);
}

// Random overlapping pairs, random associations: the total force on a is
// exactly minus the total on b (partition of unity), and equals the sparse
// matrix formulation D * sphere_forces.
TEST(ContactResponse, MomentumIsConservedAndMatchesSparseMap) {
  std::mt19937 rng(0);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_int_distribution<int> node(0, 19);
  std::vector<Sphere> la, lb;
  std::vector<std::vector<int>> aa{{0, 1}}, ab{{2}};
  for (int i = 0; i < 30; ++i) {
    la.push_back({u(rng), u(rng), u(rng), 0.6});
    lb.push_back({u(rng), u(rng), u(rng), 0.6});
    std::vector<int> na(1 + i % 4), nb(1 + i % 3);
    for (int& n : na) n = node(rng);
    for (int& n : nb) n = node(rng);
    aa.push_back(na);
    ab.push_back(nb);
  }
  const SphereTree a = make_tree(la, aa), b = make_tree(lb, ab, {0.5, -0.25, 0.1, 10});
  CollisionResult r;
  for (int i = 1; i <= 30; ++i)
    for (int j = 1; j <= 30; ++j) r.colliding.push_back({i, j});
  r.interrupted = true;
  r.untested.push_back({0, 0});  // the roots, assumed colliding
  MatX3d fa = MatX3d::Zero(20, 3), fb = MatX3d::Zero(20, 3);
  const ContactStats s = apply_contact_forces(a, b, r, {}, fa, fb);
  EXPECT_GT(s.active_pairs, 100);
  const Eigen::RowVector3d ta = fa.colwise().sum(), tb = fb.colwise().sum();
  EXPECT_LT((ta + tb).norm(), 1e-10 * ta.norm());
  EXPECT_LT((ta.transpose() - s.total_force_a).norm(), 1e-10 * ta.norm());
  EXPECT_GT(ta.norm(), 0.0);

  // Sparse formulation: per-sphere forces, then D * F.
  MatX3d Fa = MatX3d::Zero(a.num_nodes(), 3);
  auto add_pair = [&](const NodePair& p) {
    const Eigen::Vector3d d = b.spheres[p.b].center() - a.spheres[p.a].center();
    const double delta = a.spheres[p.a].r + b.spheres[p.b].r - d.norm();
    if (delta > 0) Fa.row(p.a) -= (1e3 * delta * d.normalized()).transpose();
  };
  for (const NodePair& p : r.colliding) add_pair(p);
  for (const NodePair& p : r.untested) add_pair(p);
  const MatX3d via_matrix = sphere_to_node_matrix(a, 20) * Fa;
  EXPECT_LT((via_matrix - fa).cwiseAbs().maxCoeff(), 1e-9 * fa.cwiseAbs().maxCoeff());
}

// The paper's literal per-node averaging loses momentum balance when nodes
// receive different numbers of forces; we keep it only as an option.
TEST(ContactResponse, PaperAverageIsNotMomentumConserving) {
  const SphereTree a = make_tree({{0, 0, 0, 1}, {0.1, 0, 0, 1}}, {{0}, {0}, {0}});
  const SphereTree b = make_tree({{1.5, 0, 0, 1}, {1.6, 0, 0, 1}}, {{0}, {0}, {1}});
  CollisionResult r;
  r.colliding = {{1, 1}, {2, 2}};
  MatX3d fa = MatX3d::Zero(1, 3), fb = MatX3d::Zero(2, 3);
  ContactOptions o;
  o.distribution = ContactDistribution::PaperAverage;
  apply_contact_forces(a, b, r, o, fa, fb);
  // a's single node averages two equal forces; b's two nodes get one each.
  EXPECT_NEAR(fa(0, 0), -500.0, 1e-9);
  EXPECT_NEAR(fb.col(0).sum(), 1000.0, 1e-9);
}

TEST(ContactResponse, CoincidentCentresGiveFiniteForceAlongFallback) {
  const SphereTree a = make_tree({{1, 1, 1, 1}}, {{0}, {0}});
  const SphereTree b = make_tree({{1, 1, 1, 1}}, {{0}, {0}});
  CollisionResult r;
  r.colliding = {{1, 1}};
  MatX3d fa = MatX3d::Zero(1, 3), fb = MatX3d::Zero(1, 3);
  ContactOptions o;
  o.coincident_direction = {0, 0, 0};  // degenerate fallback too -> +z
  apply_contact_forces(a, b, r, o, fa, fb);
  EXPECT_TRUE(fa.allFinite());
  EXPECT_NEAR(fb(0, 2), 2e3, 1e-9);
  EXPECT_NEAR(fa(0, 2), -2e3, 1e-9);
}

TEST(ContactResponse, BadParametersThrow) {
  const SphereTree a = make_tree({{0, 0, 0, 1}}, {{0}, {5}});
  CollisionResult r;
  MatX3d fa = MatX3d::Zero(1, 3), fb = MatX3d::Zero(1, 3);
  ContactOptions o;
  o.stiffness = -1;
  EXPECT_THROW(apply_contact_forces(a, a, r, o, fa, fb), ParameterError);
  o.stiffness = 1;
  // The association is checked where a pair uses it (O(pairs) per call, not
  // O(tree)): sphere 1 refers to node 5 of 1.
  EXPECT_NO_THROW(apply_contact_forces(a, a, r, o, fa, fb));
  r.untested.push_back({0, 1});
  const auto message = [&] {
    try {
      apply_contact_forces(a, a, r, o, fa, fb);
    } catch (const ParameterError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message().find("tree b refers to coarse node 5 but the object has 1"), std::string::npos)
      << message();
  r.untested = {{0, 0}};
  EXPECT_NO_THROW(apply_contact_forces(a, a, r, o, fa, fb));
  r.colliding.push_back({7, 0});  // no sphere 7
  EXPECT_NE(message().find("names sphere 7 of tree a, which has 2"), std::string::npos) << message();
  SphereTree none = a;
  none.assoc_offset.clear();
  EXPECT_THROW(apply_contact_forces(none, none, r, {}, fa, fb), ParameterError);
}

}  // namespace
}  // namespace icd::coupling

namespace icd::coupling {
namespace {

// Mass-weighted distribution: node n of V_i gets F m_n / sum m, so all nodes
// of a sphere accelerate alike; momentum still balances; the reported rate
// is k (1/M_a + 1/M_b) with M the sphere's node-mass sum.
TEST(ContactResponse, MassWeightedGivesEqualAccelerations) {
  const SphereTree a = make_tree({{0, 0, 0, 1}}, {{0, 1, 2}, {0, 1, 2}});
  const SphereTree b = make_tree({{1.5, 0, 0, 1}}, {{0, 1}, {0, 1}});
  const Eigen::VectorXd ma = (Eigen::VectorXd(3) << 1.0, 2.0, 5.0).finished();
  const Eigen::VectorXd mb = (Eigen::VectorXd(2) << 0.5, 1.5).finished();
  CollisionResult r;
  r.colliding = {{1, 1}};
  MatX3d fa = MatX3d::Zero(3, 3), fb = MatX3d::Zero(2, 3);
  ContactOptions o;
  o.distribution = ContactDistribution::MassWeighted;
  o.stiffness = 100;
  o.mass_a = &ma;
  o.mass_b = &mb;
  const ContactStats s = apply_contact_forces(a, b, r, o, fa, fb);
  // Total |F| = k delta = 100 * 0.5 = 50 N along x.
  for (int n = 0; n < 3; ++n) EXPECT_NEAR(fa(n, 0) / ma[n], -50.0 / 8.0, 1e-12);
  for (int n = 0; n < 2; ++n) EXPECT_NEAR(fb(n, 0) / mb[n], 50.0 / 2.0, 1e-12);
  EXPECT_NEAR(fa.col(0).sum() + fb.col(0).sum(), 0.0, 1e-12);
  EXPECT_NEAR(s.max_rate, 100 * (1.0 / 8.0 + 1.0 / 2.0), 1e-12);
  o.mass_b = nullptr;
  EXPECT_THROW(apply_contact_forces(a, b, r, o, fa, fb), ParameterError);
  const Eigen::VectorXd bad = (Eigen::VectorXd(2) << 0.5, 0.0).finished();
  o.mass_b = &bad;
  EXPECT_THROW(apply_contact_forces(a, b, r, o, fa, fb), ParameterError);
}

// The node rate cap: 40 leaf pairs all on node 0 of each object (rate
// 40 k / m, far above the cap) and one pair on nodes 1 of both (rate k / m,
// below it). The crowded pairs are weighted to exactly the cap on node 0
// (reference: k delta summed by hand, times cap / rate), the lone pair keeps
// the full k, and the forces stay equal and opposite.
TEST(ContactResponse, NodeRateCapHoldsEachNodeAtTheCapAndSparesTheOthers) {
  const int crowd = 40;
  std::vector<Sphere> la, lb;
  std::vector<std::vector<int>> aa = {{0}}, ab = {{0}};
  for (int i = 0; i < crowd; ++i) {
    la.push_back({0.01 * i, 0, 0, 0.5});
    lb.push_back({0.01 * i, 0, 0.6 + 0.001 * i, 0.5});  // penetration 0.4 - 0.001 i
    aa.push_back({0});
    ab.push_back({0});
  }
  la.push_back({5, 0, 0, 0.5});
  lb.push_back({5, 0, 0.9, 0.5});  // penetration 0.1, nodes 1
  aa.push_back({1});
  ab.push_back({1});
  const SphereTree a = make_tree(la, aa), b = make_tree(lb, ab);
  CollisionResult r;
  for (int i = 1; i <= crowd + 1; ++i) r.colliding.push_back({i, i});
  const Eigen::VectorXd ma = (Eigen::VectorXd(2) << 2.0, 2.0).finished();
  const Eigen::VectorXd mb = (Eigen::VectorXd(2) << 4.0, 4.0).finished();
  ContactOptions o;
  o.stiffness = 100;
  o.mass_a = &ma;
  o.mass_b = &mb;
  MatX3d fa0 = MatX3d::Zero(2, 3), fb0 = MatX3d::Zero(2, 3);
  const ContactStats raw = apply_contact_forces(a, b, r, o, fa0, fb0);
  EXPECT_EQ(raw.capped_pairs, 0);
  const double cap = 500;  // 1/s^2: node 0 of a has 40 * 100 / 2 = 2000, of b 1000
  o.node_rate_limit = cap;
  MatX3d fa = MatX3d::Zero(2, 3), fb = MatX3d::Zero(2, 3);
  const ContactStats s = apply_contact_forces(a, b, r, o, fa, fb);
  EXPECT_EQ(s.capped_pairs, crowd);
  EXPECT_NEAR(s.min_weight, cap / 2000.0, 1e-15);
  double sum_delta = 0;
  for (int i = 0; i < crowd; ++i) sum_delta += 0.4 - 0.001 * i;
  // Weighted by the more loaded side (a: 2000 / s^2): w = 0.25.
  EXPECT_NEAR(fb(0, 2), 0.25 * 100 * sum_delta, 1e-9);
  EXPECT_NEAR(fa(0, 2), -0.25 * 100 * sum_delta, 1e-9);
  EXPECT_NEAR(fb(1, 2), 100 * 0.1, 1e-12);  // the lone pair: full k
  EXPECT_EQ(fb(1, 2), fb0(1, 2));
  EXPECT_LT((fa.colwise().sum() + fb.colwise().sum()).norm(), 1e-12);
  // Every node's rate at most the cap on each side; the raw response's was 4x.
  EXPECT_LE(s.max_rate, 2 * cap * (1 + 1e-12));
  EXPECT_NEAR(raw.max_rate, 2000 + 1000, 1e-9);
  // Without masses a cap cannot be computed.
  o.mass_a = nullptr;
  EXPECT_THROW(apply_contact_forces(a, b, r, o, fa, fb), ParameterError);
}

// A node touched by two objects (the middle one of a row of three): each
// pair alone loads node 0 of b with k / m = 100 / s^2, under a cap of 150,
// so capped pair by pair neither is weighted and the node gets 200 in all.
// With the totals over both pairs (add_contact_rates) both are weighted by
// 150 / 200 and the node gets exactly the cap; the applied rates are
// reported for the caller's bound, and each pair's forces stay equal and
// opposite.
TEST(ContactResponse, NodeRateCapCountsEveryPairOfANode) {
  const SphereTree a = make_tree({{0, 0, 0, 0.5}}, {{0}, {0}});
  const SphereTree b = make_tree({{0, 0, 0.8, 0.5}}, {{0}, {0}});  // the middle object
  const SphereTree c = make_tree({{0, 0, 1.5, 0.5}}, {{0}, {0}});
  CollisionResult r;
  r.colliding = {{1, 1}};  // a-b: penetration 0.2; b-c: 0.3
  const Eigen::VectorXd ma = Eigen::VectorXd::Constant(1, 10.0);
  const Eigen::VectorXd mb = Eigen::VectorXd::Constant(1, 1.0);
  const Eigen::VectorXd mc = Eigen::VectorXd::Constant(1, 10.0);
  ContactOptions ab, bc;
  ab.stiffness = bc.stiffness = 100;
  ab.node_rate_limit = bc.node_rate_limit = 150;
  ab.mass_a = &ma;
  ab.mass_b = &mb;
  bc.mass_a = &mb;
  bc.mass_b = &mc;
  // Pair by pair: no weight.
  MatX3d fa = MatX3d::Zero(1, 3), fb = MatX3d::Zero(1, 3), fc = MatX3d::Zero(1, 3);
  EXPECT_EQ(apply_contact_forces(a, b, r, ab, fa, fb).capped_pairs, 0);
  EXPECT_EQ(apply_contact_forces(b, c, r, bc, fb, fc).capped_pairs, 0);
  EXPECT_NEAR(fb(0, 2), 100 * 0.2 - 100 * 0.3, 1e-12);
  // Totals over both pairs.
  Eigen::VectorXd total_a = Eigen::VectorXd::Zero(1), total_b = Eigen::VectorXd::Zero(1),
                  total_c = Eigen::VectorXd::Zero(1);
  add_contact_rates(a, b, r, ab, total_a, total_b);
  add_contact_rates(b, c, r, bc, total_b, total_c);
  EXPECT_NEAR(total_b[0], 200, 1e-12);
  EXPECT_NEAR(total_a[0], 10, 1e-12);
  Eigen::VectorXd applied_a = Eigen::VectorXd::Zero(1), applied_b = Eigen::VectorXd::Zero(1),
                  applied_c = Eigen::VectorXd::Zero(1);
  ab.total_rate_a = &total_a;
  ab.total_rate_b = &total_b;
  ab.applied_rate_a = &applied_a;
  ab.applied_rate_b = &applied_b;
  bc.total_rate_a = &total_b;
  bc.total_rate_b = &total_c;
  bc.applied_rate_a = &applied_b;
  bc.applied_rate_b = &applied_c;
  fa.setZero();
  fb.setZero();
  fc.setZero();
  const ContactStats s1 = apply_contact_forces(a, b, r, ab, fa, fb);
  const MatX3d fb_ab = fb;
  const ContactStats s2 = apply_contact_forces(b, c, r, bc, fb, fc);
  EXPECT_EQ(s1.capped_pairs, 1);
  EXPECT_EQ(s2.capped_pairs, 1);
  EXPECT_NEAR(s1.min_weight, 0.75, 1e-15);
  EXPECT_NEAR(fa(0, 2), -0.75 * 100 * 0.2, 1e-12);
  EXPECT_NEAR(fb_ab(0, 2), 0.75 * 100 * 0.2, 1e-12);
  EXPECT_NEAR(fc(0, 2), 0.75 * 100 * 0.3, 1e-12);
  EXPECT_NEAR(fb(0, 2), 0.75 * 100 * (0.2 - 0.3), 1e-12);
  EXPECT_NEAR(applied_b[0], 150, 1e-9);  // the cap, over both pairs
  EXPECT_NEAR(applied_a[0], 7.5, 1e-12);
  EXPECT_NEAR(applied_c[0], 7.5, 1e-12);
  // Totals of the wrong size are refused; rates need the masses.
  const Eigen::VectorXd wrong = Eigen::VectorXd::Zero(2);
  ab.total_rate_b = &wrong;
  EXPECT_THROW(apply_contact_forces(a, b, r, ab, fa, fb), ParameterError);
  ab.mass_a = nullptr;
  EXPECT_THROW(add_contact_rates(a, b, r, ab, total_a, total_b), ParameterError);
}

double kinetic(const MatX3d& v, const Eigen::VectorXd& m) {
  return 0.5 * (v.rowwise().squaredNorm().transpose() * m).value();
}

// The deep-contact velocity step: a leaf pair deeper than its radius whose
// spheres approach loses exactly its relative normal approach velocity
// (mass-weighted means of the nodes), keeps the tangential part and the
// momentum, and the kinetic energy drops by (1/2) mu v_n^2. A separating
// pair, a shallow pair and a deep pair below the threshold are untouched.
TEST(ContactResponse, DeepContactStepStopsTheApproachAndOnlyRemovesEnergy) {
  const Eigen::Vector3d n = Eigen::Vector3d(2, -1, 2) / 3.0;
  const Eigen::Vector3d cb = 0.5 * n;  // radii 0.4: penetration 0.3 (0.75 r)
  const SphereTree a = make_tree({{0, 0, 0, 0.4}}, {{0, 1}, {0, 1}});
  const SphereTree b = make_tree({{cb.x(), cb.y(), cb.z(), 0.4}}, {{0, 1, 2}, {0, 1, 2}});
  CollisionResult r;
  r.colliding = {{1, 1}};
  const Eigen::VectorXd ma = (Eigen::VectorXd(2) << 1.0, 3.0).finished();
  const Eigen::VectorXd mb = (Eigen::VectorXd(3) << 0.5, 2.0, 1.5).finished();
  std::mt19937 rng(3);
  std::normal_distribution<double> g(0, 1);
  auto draw = [&](int rows) {
    MatX3d v(rows, 3);
    for (int i = 0; i < rows; ++i) v.row(i) << g(rng), g(rng), g(rng);
    return v;
  };
  auto mean = [](const MatX3d& v, const Eigen::VectorXd& m) {
    return Eigen::Vector3d(v.transpose() * m / m.sum());
  };
  int approached = 0;
  for (int trial = 0; trial < 20; ++trial) {
    MatX3d va = draw(2), vb = draw(3);
    const MatX3d va0 = va, vb0 = vb;
    const double vn0 = (mean(vb, mb) - mean(va, ma)).dot(n);
    const DeepContactStats s = deep_contact_velocity_step(a, b, r, ma, mb, va, vb, 0.5);
    EXPECT_EQ(s.pairs, 1);
    const Eigen::Vector3d p0 = va0.transpose() * ma + vb0.transpose() * mb;
    const Eigen::Vector3d p1 = va.transpose() * ma + vb.transpose() * mb;
    EXPECT_LT((p1 - p0).norm(), 1e-12);
    const double e0 = kinetic(va0, ma) + kinetic(vb0, mb), e1 = kinetic(va, ma) + kinetic(vb, mb);
    if (vn0 < 0) {
      ++approached;
      EXPECT_EQ(s.approaching, 1);
      EXPECT_NEAR((mean(vb, mb) - mean(va, ma)).dot(n), 0.0, 1e-12);
      const double mu = ma.sum() * mb.sum() / (ma.sum() + mb.sum());
      EXPECT_NEAR(e0 - e1, 0.5 * mu * vn0 * vn0, 1e-12);
      EXPECT_NEAR(s.removed_energy, e0 - e1, 1e-12);
      // Relative velocities within each object are kept (a uniform shift).
      EXPECT_LT(((va.row(1) - va.row(0)) - (va0.row(1) - va0.row(0))).norm(), 1e-12);
    } else {
      EXPECT_EQ(s.approaching, 0);
      EXPECT_EQ(va, va0);
      EXPECT_EQ(vb, vb0);
    }
  }
  EXPECT_GT(approached, 3);
  EXPECT_LT(approached, 17);
  // Above the threshold only: at depth ratio 0.8 (> 0.75) nothing moves.
  MatX3d va = MatX3d::Zero(2, 3), vb = MatX3d::Zero(3, 3);
  va.col(0).setConstant(1.0);
  vb.col(0).setConstant(-1.0);
  const MatX3d va0 = va;
  EXPECT_EQ(deep_contact_velocity_step(a, b, r, ma, mb, va, vb, 0.8).pairs, 0);
  EXPECT_EQ(va, va0);
  const Eigen::VectorXd short_mass = Eigen::VectorXd::Ones(1);
  EXPECT_THROW(deep_contact_velocity_step(a, b, r, short_mass, mb, va, vb), ParameterError);
}

// Mirror symmetry of the deep-contact step: tree b is tree a reflected in
// the plane x = 0 (sphere i of b is the mirror of sphere i of a, tied to the
// same node numbers, nodes sharing spheres), with mirrored node masses and
// velocities; the deep pairs (i, j) and (j, i) are mirror images of each
// other. The step must give mirror-image velocities (so no sideways impulse
// on either object), whatever the order of the pairs and whichever object
// is a, keep the momentum and never add kinetic energy. Reference: the
// reflection itself and the sums before the step. (A pair-by-pair sweep
// treats (i, j) before (j, i) and fails the mirror.)
TEST(ContactResponse, DeepContactStepIsMirrorSymmetricAndOrderFree) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  const Eigen::Vector3d mirror(-1, 1, 1);
  int stepped = 0;
  for (int trial = 0; trial < 20; ++trial) {
    const int leaves = 5, nodes = leaves + 1;
    std::vector<Sphere> la, lb;
    std::vector<std::vector<int>> assoc{{0, 1, 2, 3, 4, 5}};  // the root
    for (int i = 0; i < leaves; ++i) {
      const Eigen::Vector3d c(-0.08 + 0.03 * u(rng), 0.12 * u(rng), 0.12 * u(rng));
      const double r = 0.3 + 0.05 * u(rng);
      la.push_back({c.x(), c.y(), c.z(), r});
      lb.push_back({-c.x(), c.y(), c.z(), r});
      assoc.push_back({i, i + 1});  // neighbouring spheres share a node
    }
    const SphereTree a = make_tree(la, assoc), b = make_tree(lb, assoc);
    CollisionResult r;
    for (int i = 1; i <= leaves; ++i)
      for (int j = 1; j <= leaves; ++j) r.colliding.push_back({i, j});
    Eigen::VectorXd ma(nodes);
    MatX3d va(nodes, 3);
    for (int n = 0; n < nodes; ++n) {
      ma[n] = 1.0 + 0.9 * u(rng);
      va.row(n) << 0.5 + u(rng), u(rng), u(rng);  // a moves towards +x, b towards -x
    }
    const Eigen::VectorXd mb = ma;
    MatX3d vb = va.array().rowwise() * mirror.transpose().array();
    const MatX3d va0 = va, vb0 = vb;
    const DeepContactStats s = deep_contact_velocity_step(a, b, r, ma, mb, va, vb, 0.5);
    ASSERT_GT(s.pairs, 0) << "trial " << trial;
    stepped += s.approaching > 0;
    // Mirror images.
    const MatX3d va_mirrored = va.array().rowwise() * mirror.transpose().array();
    EXPECT_LT((vb - va_mirrored).cwiseAbs().maxCoeff(), 1e-12) << "trial " << trial;
    // Momentum kept, kinetic energy not gained; no sideways momentum moved.
    const Eigen::Vector3d p0a = va0.transpose() * ma, p0b = vb0.transpose() * mb;
    const Eigen::Vector3d p1a = va.transpose() * ma, p1b = vb.transpose() * mb;
    EXPECT_LT((p1a + p1b - p0a - p0b).norm(), 1e-12);
    EXPECT_LT((p1a - p0a).tail<2>().norm(), 1e-12);
    const double e0 = kinetic(va0, ma) + kinetic(vb0, mb), e1 = kinetic(va, ma) + kinetic(vb, mb);
    EXPECT_LE(e1, e0 + 1e-12);
    EXPECT_NEAR(e0 - e1, s.removed_energy, 1e-12);
    // The pairs in reverse order, and b as object a: the same velocities.
    CollisionResult reversed, swapped;
    reversed.colliding.assign(r.colliding.rbegin(), r.colliding.rend());
    for (const NodePair& p : r.colliding) swapped.colliding.push_back({p.b, p.a});
    MatX3d va2 = va0, vb2 = vb0, va3 = va0, vb3 = vb0;
    deep_contact_velocity_step(a, b, reversed, ma, mb, va2, vb2, 0.5);
    deep_contact_velocity_step(b, a, swapped, mb, ma, vb3, va3, 0.5);
    EXPECT_LT((va2 - va).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LT((vb2 - vb).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LT((va3 - va).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LT((vb3 - vb).cwiseAbs().maxCoeff(), 1e-12);
  }
  EXPECT_GT(stepped, 10);
}

// Kinetic energy is never gained and momentum is kept, on random
// non-symmetric pairs of trees (several patches, random velocities), and
// every patch that stepped no longer approaches along its normal.
TEST(ContactResponse, DeepContactStepNeverGainsEnergyOnRandomTrees) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 50; ++trial) {
    const int leaves = 8, nodes = 12;
    std::uniform_int_distribution<int> pick(0, nodes - 1);
    std::vector<Sphere> la, lb;
    std::vector<std::vector<int>> aa{{0}}, ab{{0}};
    for (int i = 0; i < leaves; ++i) {
      la.push_back({-0.1 + 0.1 * u(rng), 0.3 * u(rng), 0.3 * u(rng), 0.3});
      lb.push_back({0.1 + 0.1 * u(rng), 0.3 * u(rng), 0.3 * u(rng), 0.3});
      aa.push_back({pick(rng), pick(rng)});
      ab.push_back({pick(rng)});
    }
    const SphereTree a = make_tree(la, aa), b = make_tree(lb, ab);
    CollisionResult r;
    for (int i = 1; i <= leaves; ++i)
      for (int j = 1; j <= leaves; ++j) r.colliding.push_back({i, j});
    Eigen::VectorXd ma(nodes), mb(nodes);
    MatX3d va(nodes, 3), vb(nodes, 3);
    for (int n = 0; n < nodes; ++n) {
      ma[n] = 1.0 + 0.9 * u(rng);
      mb[n] = 1.0 + 0.9 * u(rng);
      va.row(n) << u(rng), u(rng), u(rng);
      vb.row(n) << u(rng), u(rng), u(rng);
    }
    const MatX3d va0 = va, vb0 = vb;
    const DeepContactStats s = deep_contact_velocity_step(a, b, r, ma, mb, va, vb, 0.3);
    const Eigen::Vector3d p0 = va0.transpose() * ma + vb0.transpose() * mb;
    const Eigen::Vector3d p1 = va.transpose() * ma + vb.transpose() * mb;
    EXPECT_LT((p1 - p0).norm(), 1e-12) << "trial " << trial;
    const double e0 = kinetic(va0, ma) + kinetic(vb0, mb), e1 = kinetic(va, ma) + kinetic(vb, mb);
    EXPECT_LE(e1, e0 + 1e-12) << "trial " << trial;
    EXPECT_NEAR(e0 - e1, s.removed_energy, 1e-12);
    EXPECT_GE(s.removed_energy, 0.0);
  }
}

}  // namespace
}  // namespace icd::coupling
