#include <icd/collision/swept_spheres.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>

#include <icd/mesh/core/error.hpp>

namespace icd::collision {

bool swept_overlap(const SweptSphere& a, const SweptSphere& b) {
  // Relative motion: d(t) = e0 + t e, closest approach at t* = -e0.e / e.e in [0, 1].
  const double ex = b.x - a.x, ey = b.y - a.y, ez = b.z - a.z;
  const double vx = b.dx - a.dx, vy = b.dy - a.dy, vz = b.dz - a.dz;
  const double vv = vx * vx + vy * vy + vz * vz;
  double t = vv > 0 ? -(ex * vx + ey * vy + ez * vz) / vv : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  const double px = ex + t * vx, py = ey + t * vy, pz = ez + t * vz;
  const double rr = a.r + b.r;
  return px * px + py * py + pz * pz <= rr * rr;
}

double sweep_spheres(std::span<const Sphere> from, std::span<const Sphere> to,
                     std::vector<SweptSphere>& out, std::span<const Sphere> via) {
  if (from.size() != to.size() || (!via.empty() && via.size() != from.size()))
    throw ParameterError("sweep_spheres: " + std::to_string(from.size()) + " start spheres, " +
                         std::to_string(to.size()) + " end spheres, " +
                         std::to_string(via.size()) + " via spheres");
  out.resize(from.size());
  double motion = 0;
  for (std::size_t i = 0; i < from.size(); ++i) {
    const Sphere& a = from[i];
    const Sphere& b = to[i];
    SweptSphere& s = out[i];
    s = {a.x, a.y, a.z, b.x - a.x, b.y - a.y, b.z - a.z, std::max(a.r, b.r)};
    const double len2 = s.dx * s.dx + s.dy * s.dy + s.dz * s.dz;
    if (!via.empty()) {
      // Distance from via's centre to the segment, plus via's radius.
      const Sphere& v = via[i];
      const double wx = v.x - a.x, wy = v.y - a.y, wz = v.z - a.z;
      const double t =
          len2 > 0 ? std::clamp((wx * s.dx + wy * s.dy + wz * s.dz) / len2, 0.0, 1.0) : 0.0;
      const double qx = wx - t * s.dx, qy = wy - t * s.dy, qz = wz - t * s.dz;
      s.r = std::max(s.r, std::sqrt(qx * qx + qy * qy + qz * qz) + v.r);
    }
    s.r *= 1 + 1e-12;  // rounding
    motion = std::max(motion, std::sqrt(len2) + std::max(0.0, b.r - a.r));
  }
  return motion;
}

void still_spheres(std::span<const Sphere> spheres, std::vector<SweptSphere>& out) {
  out.resize(spheres.size());
  for (std::size_t i = 0; i < spheres.size(); ++i) {
    const Sphere& s = spheres[i];
    out[i] = {s.x, s.y, s.z, 0, 0, 0, s.r};
  }
}

SweptResult swept_contact(const SphereTree& a, std::span<const SweptSphere> sa,
                          const SphereTree& b, std::span<const SweptSphere> sb,
                          const SweptRequest& request, std::vector<NodePair>& stack) {
  if (sa.size() != a.spheres.size() || sb.size() != b.spheres.size())
    throw ParameterError("swept_contact: one swept sphere per tree node expected");
  SweptResult res;
  if (a.spheres.empty() || b.spheres.empty()) return res;
  using Clock = std::chrono::steady_clock;
  const bool timed = std::isfinite(request.budget_seconds);
  const Clock::time_point deadline =
      timed ? Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                 std::chrono::duration<double>(request.budget_seconds))
            : Clock::time_point{};
  stack.clear();
  stack.push_back({0, 0});
  while (!stack.empty()) {
    if ((request.budget_tests >= 0 && res.tests >= request.budget_tests) ||
        (timed && (res.tests & 63) == 0 && Clock::now() > deadline)) {
      res.touched = res.gave_up = true;
      return res;
    }
    const NodePair p = stack.back();
    stack.pop_back();
    ++res.tests;
    if (!swept_overlap(sa[p.a], sb[p.b])) continue;
    const bool leaf_a = a.is_leaf(p.a), leaf_b = b.is_leaf(p.b);
    if (leaf_a && leaf_b) {
      res.touched = true;
      res.first = p;
      return res;
    }
    // Split the larger sphere (or the one that is not a leaf).
    if (!leaf_a && (leaf_b || sa[p.a].r >= sb[p.b].r)) {
      for (int c = a.first_child[p.a], e = c + a.child_count[p.a]; c < e; ++c)
        stack.push_back({c, p.b});
    } else {
      for (int c = b.first_child[p.b], e = c + b.child_count[p.b]; c < e; ++c)
        stack.push_back({p.a, c});
    }
  }
  return res;
}

}  // namespace icd::collision
