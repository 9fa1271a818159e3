#include <icd/collision/exact_predicates.hpp>

#include <cmath>
#include <limits>
#include <vector>

namespace icd::collision {
namespace {

// Expansions: sums of non-overlapping doubles, increasing magnitude.
using Expansion = std::vector<double>;

inline void two_sum(double a, double b, double& x, double& y) {
  x = a + b;
  const double bv = x - a, av = x - bv;
  y = (a - av) + (b - bv);
}

inline void two_product(double a, double b, double& x, double& y) {
  x = a * b;
  y = std::fma(a, b, -x);
}

// e + b (Shewchuk's GROW-EXPANSION).
Expansion grow(const Expansion& e, double b) {
  Expansion h;
  h.reserve(e.size() + 1);
  double q = b;
  for (double ei : e) {
    double hi;
    two_sum(q, ei, q, hi);
    h.push_back(hi);
  }
  h.push_back(q);
  return h;
}

Expansion add(const Expansion& e, const Expansion& f) {
  Expansion r = e;
  for (double x : f)
    if (x != 0.0) r = grow(r, x);
  return r;
}

Expansion scale(const Expansion& e, double b) {
  Expansion r{0.0};
  for (double ei : e) {
    double hi, lo;
    two_product(ei, b, hi, lo);
    if (lo != 0.0) r = grow(r, lo);
    if (hi != 0.0) r = grow(r, hi);
  }
  return r;
}

Expansion mul(const Expansion& e, const Expansion& f) {
  Expansion r{0.0};
  for (double fj : f)
    if (fj != 0.0) r = add(r, scale(e, fj));
  return r;
}

Expansion neg(Expansion e) {
  for (double& x : e) x = -x;
  return e;
}

Expansion diff(double a, double b) {
  double x, y;
  two_sum(a, -b, x, y);
  return {y, x};
}

int sign(const Expansion& e) {
  for (auto it = e.rbegin(); it != e.rend(); ++it)
    if (*it != 0.0) return *it > 0 ? 1 : -1;
  return 0;
}

// det[u; v] for 2-vectors of expansions.
Expansion det2(const Expansion& ux, const Expansion& uy, const Expansion& vx, const Expansion& vy) {
  return add(mul(ux, vy), neg(mul(uy, vx)));
}

constexpr double kEps = std::numeric_limits<double>::epsilon() * 0.5;

}  // namespace

int orient3d(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
             const Eigen::Vector3d& d) {
  const double bax = b.x() - a.x(), bay = b.y() - a.y(), baz = b.z() - a.z();
  const double cax = c.x() - a.x(), cay = c.y() - a.y(), caz = c.z() - a.z();
  const double dax = d.x() - a.x(), day = d.y() - a.y(), daz = d.z() - a.z();
  const double m1 = cay * daz - caz * day, m2 = caz * dax - cax * daz, m3 = cax * day - cay * dax;
  const double det = bax * m1 + bay * m2 + baz * m3;
  const double permanent = std::abs(bax) * (std::abs(cay * daz) + std::abs(caz * day)) +
                           std::abs(bay) * (std::abs(caz * dax) + std::abs(cax * daz)) +
                           std::abs(baz) * (std::abs(cax * day) + std::abs(cay * dax));
  // Generous bound (Shewchuk's o3derrboundA is (7 + 56 eps) eps); differences
  // of the inputs are rounded too, hence the larger constant.
  const double bound = 16.0 * kEps * permanent;
  if (det > bound) return 1;
  if (-det > bound) return -1;
  if (permanent == 0.0 && bax == 0.0 && bay == 0.0 && baz == 0.0) return 0;
  const Expansion Bx = diff(b.x(), a.x()), By = diff(b.y(), a.y()), Bz = diff(b.z(), a.z());
  const Expansion Cx = diff(c.x(), a.x()), Cy = diff(c.y(), a.y()), Cz = diff(c.z(), a.z());
  const Expansion Dx = diff(d.x(), a.x()), Dy = diff(d.y(), a.y()), Dz = diff(d.z(), a.z());
  const Expansion M1 = det2(Cy, Cz, Dy, Dz), M2 = det2(Cz, Cx, Dz, Dx), M3 = det2(Cx, Cy, Dx, Dy);
  return sign(add(add(mul(Bx, M1), mul(By, M2)), mul(Bz, M3)));
}

int orient2d(double ax, double ay, double bx, double by, double cx, double cy) {
  const double l = (bx - ax) * (cy - ay), r = (by - ay) * (cx - ax);
  const double det = l - r;
  const double bound = 8.0 * kEps * (std::abs(l) + std::abs(r));
  if (det > bound) return 1;
  if (-det > bound) return -1;
  return sign(det2(diff(bx, ax), diff(by, ay), diff(cx, ax), diff(cy, ay)));
}

}  // namespace icd::collision
