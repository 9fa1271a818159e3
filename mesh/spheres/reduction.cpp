#include <icd/mesh/spheres/reduction.hpp>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <string>

#include <Eigen/Geometry>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/convex_hull_3.h>

#include <icd/mesh/core/error.hpp>
#include <icd/mesh/core/primitives.hpp>
#include <icd/mesh/spheres/parallel.hpp>

namespace icd::mesh {

std::vector<int> farthest_members(const MatX3d& points, const std::vector<int>& members,
                                  const MatX3d& dirs) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  std::vector<int> arg(static_cast<size_t>(dirs.rows()), members.empty() ? -1 : members.front());
  if (members.empty()) return arg;
  auto value = [](double d0, double d1, double d2, double x, double y, double z) {
    return d0 * x + d1 * y + d2 * z;
  };
  // Members bucketed by the cells of a grid over their bounding box (a
  // counting sort of their positions), each cell with the bounding box of
  // its members. The value of a member along d, fl(fl(d0 x + d1 y) + d2 z)
  // with every product rounded, is at most the same expression on its
  // cell's box corner farthest along d: rounding is monotone, so the bound
  // holds in floating point too, and only cells whose bound reaches the
  // best value found are scanned (with a slack far above a few roundings of
  // the terms, in case a compiler evaluates the two expressions differently,
  // e.g. contracted to fused multiply-adds: scanning more never changes the
  // answer).
  const size_t n = members.size();
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(inf), hi = Eigen::Vector3d::Constant(-inf);
  for (int s : members) {
    lo = lo.cwiseMin(points.row(s).transpose());
    hi = hi.cwiseMax(points.row(s).transpose());
  }
  // About 64 members per occupied cell on a surface (about 4 G^2 cells occupied).
  const int g = std::clamp(static_cast<int>(std::sqrt(static_cast<double>(n) / 256.0)), 1, 128);
  const Eigen::Vector3d extent = (hi - lo).cwiseMax(1e-300);
  auto cell_of = [&](int s) {
    int c = 0;
    for (int k = 0; k < 3; ++k) {
      const int i = std::min(g - 1, static_cast<int>((points(s, k) - lo[k]) / extent[k] * g));
      c = c * g + std::max(0, i);
    }
    return c;
  };
  const auto cells = static_cast<size_t>(g) * static_cast<size_t>(g) * static_cast<size_t>(g);
  std::vector<int> cell(n);
  std::vector<size_t> start(cells + 1, 0);
  for (size_t i = 0; i < n; ++i) {
    cell[i] = cell_of(members[i]);
    ++start[static_cast<size_t>(cell[i]) + 1];
  }
  for (size_t c = 0; c < cells; ++c) start[c + 1] += start[c];
  std::vector<size_t> order(n);  // positions in members, cell by cell, in member order
  {
    std::vector<size_t> next(start.begin(), start.end() - 1);
    for (size_t i = 0; i < n; ++i) order[next[static_cast<size_t>(cell[i])]++] = i;
  }
  struct Block {
    size_t begin, end;
    Eigen::Vector3d lo, hi;
  };
  std::vector<Block> blocks;
  for (size_t c = 0; c < cells; ++c) {
    if (start[c] == start[c + 1]) continue;
    Block b{start[c], start[c + 1], Eigen::Vector3d::Constant(inf),
            Eigen::Vector3d::Constant(-inf)};
    for (size_t k = b.begin; k < b.end; ++k) {
      b.lo = b.lo.cwiseMin(points.row(members[order[k]]).transpose());
      b.hi = b.hi.cwiseMax(points.row(members[order[k]]).transpose());
    }
    blocks.push_back(b);
  }
  std::vector<double> bound(blocks.size());
  for (Eigen::Index d = 0; d < dirs.rows(); ++d) {
    const double d0 = dirs(d, 0), d1 = dirs(d, 1), d2 = dirs(d, 2);
    const double slack = 1e-12 * (std::abs(d0) * std::max(std::abs(lo.x()), std::abs(hi.x())) +
                                  std::abs(d1) * std::max(std::abs(lo.y()), std::abs(hi.y())) +
                                  std::abs(d2) * std::max(std::abs(lo.z()), std::abs(hi.z())));
    size_t top = 0;
    for (size_t b = 0; b < blocks.size(); ++b) {
      const Block& k = blocks[b];
      bound[b] = value(d0, d1, d2, d0 >= 0 ? k.hi.x() : k.lo.x(), d1 >= 0 ? k.hi.y() : k.lo.y(),
                       d2 >= 0 ? k.hi.z() : k.lo.z());
      if (bound[b] > bound[top]) top = b;
    }
    // The first member (in member order) with the largest value, as a scan
    // of every member with "v > best" finds it.
    double best = -inf;
    size_t best_at = 0;
    auto scan = [&](const Block& b) {
      for (size_t k = b.begin; k < b.end; ++k) {
        const size_t i = order[k];
        const auto p = points.row(members[i]);
        const double v = value(d0, d1, d2, p(0), p(1), p(2));
        if (v > best || (v == best && i < best_at)) best = v, best_at = i;
      }
    };
    scan(blocks[top]);
    for (size_t b = 0; b < blocks.size(); ++b) {
      if (b != top && bound[b] + slack >= best) scan(blocks[b]);
    }
    if (best > -inf) arg[static_cast<size_t>(d)] = members[best_at];
  }
  return arg;
}

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;

constexpr double kInf = std::numeric_limits<double>::infinity();

/// Drops the members strictly inside the convex hull of their extreme
/// points along 42 directions (Akl-Toussaint prefilter): those are no hull
/// vertices. The small hull's facets are found by brute force over triples.
std::vector<int> prefilter(const MatX3d& points, const std::vector<int>& members) {
  static const MatX3d dirs = make_icosphere(1, 1.0).V;
  std::vector<int> support = farthest_members(points, members, dirs);
  std::sort(support.begin(), support.end());
  support.erase(std::unique(support.begin(), support.end()), support.end());
  const auto n = support.size();
  std::vector<Eigen::Vector3d> S;
  for (int s : support) S.emplace_back(points.row(s).transpose());
  double extent = 0;
  for (const auto& a : S) extent = std::max(extent, (a - S.front()).norm());
  const double tol = 1e-9 * extent;
  std::vector<std::pair<Eigen::Vector3d, double>> facets;  // outward normal, offset
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = i + 1; j < n; ++j) {
      for (size_t k = j + 1; k < n; ++k) {
        Eigen::Vector3d normal = (S[j] - S[i]).cross(S[k] - S[i]);
        const double len = normal.norm();
        if (!(len > 1e-12 * extent * extent)) continue;
        normal /= len;
        const double offset = normal.dot(S[i]);
        int above = 0, below = 0;
        for (const auto& q : S) {
          const double v = normal.dot(q) - offset;
          above += v > tol ? 1 : 0;
          below += v < -tol ? 1 : 0;
        }
        if (above > 0 && below > 0) continue;
        if (above == 0 && below == 0) continue;  // flat support set: no volume
        if (above > 0)
          facets.emplace_back(-normal, -offset);
        else
          facets.emplace_back(normal, offset);
      }
    }
  }
  if (facets.size() < 4) return members;
  std::vector<int> out = support;
  for (int s : members) {
    const Eigen::Vector3d p = points.row(s).transpose();
    bool inside = true;
    for (const auto& [normal, offset] : facets) {
      if (normal.dot(p) >= offset - 1e3 * tol) {
        inside = false;
        break;
      }
    }
    if (!inside) out.push_back(s);
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

/// Extreme points (convex hull vertices) of the member samples, as rows;
/// without `hull_only`, sets of over 1000 members give a superset of them
/// (the prefilter's survivors: the same farthest distance from any point,
/// without the exact hull's cost). With it, the exact hull is computed on
/// those survivors (same vertices; on the dragon's nodes of 10^4-10^5
/// samples most of the hull's cost was the points the prefilter drops).
std::vector<Eigen::Vector3d> extreme_points(const MatX3d& points,
                                            const std::vector<int>& all_members, bool hull_only) {
  std::vector<Eigen::Vector3d> out;
  if (all_members.size() <= 64) {
    for (int s : all_members) out.emplace_back(points.row(s));
    return out;
  }
  if (!hull_only && all_members.size() > 1000) {
    // The prefilter keeps every hull vertex: the farthest member from any
    // point is among its survivors.
    for (int s : prefilter(points, all_members)) out.emplace_back(points.row(s));
    return out;
  }
  // The exact hull of the prefilter's survivors has the same vertices.
  const std::vector<int> members =
      all_members.size() > 1000 ? prefilter(points, all_members) : all_members;
  std::vector<Point> in;
  in.reserve(members.size());
  for (int s : members) in.emplace_back(points(s, 0), points(s, 1), points(s, 2));
  std::vector<Point> hull;
  CGAL::extreme_points_3(in, std::back_inserter(hull));
  if (hull.empty()) {  // degenerate (coplanar) input: keep every point
    for (int s : members) out.emplace_back(points.row(s));
    return out;
  }
  for (const Point& p : hull) out.emplace_back(p.x(), p.y(), p.z());
  return out;
}

/// The member farthest along each of 162 directions (vertices of a twice
/// subdivided icosahedron), without duplicates.
std::vector<Eigen::Vector3d> support_points(const MatX3d& points, const std::vector<int>& members) {
  static const MatX3d dirs = make_icosphere(2, 1.0).V;
  std::vector<int> arg = farthest_members(points, members, dirs);
  std::sort(arg.begin(), arg.end());
  arg.erase(std::unique(arg.begin(), arg.end()), arg.end());
  std::vector<Eigen::Vector3d> out;
  for (int s : arg) out.emplace_back(points.row(s).transpose());
  return out;
}

double max_distance(const std::vector<Eigen::Vector3d>& pts, const Eigen::Vector3d& c) {
  double best = 0;
  for (const auto& p : pts) best = std::max(best, (p - c).squaredNorm());
  return std::sqrt(best);
}

void refit_radius(const ReductionProblem& problem, FittedSphere& sphere) {
  double r = 0;
  for (int s : sphere.members) {
    r = std::max(r, problem.reach(s, sphere.center));
  }
  sphere.radius = r;
  sphere.error = r - sphere.depth;
}

/// Lloyd assignment: member -> index of the sphere minimizing |s - c| - depth
/// (blocks of members on `threads` workers).
std::vector<int> assign(const ReductionProblem& problem, const std::vector<int>& members,
                        const std::vector<FittedSphere>& spheres, int threads = 1) {
  std::vector<int> owner(members.size(), 0);
  constexpr size_t kBlock = 16384;
  parallel_for((members.size() + kBlock - 1) / kBlock, threads, [&](size_t block, int) {
    const size_t end = std::min(members.size(), (block + 1) * kBlock);
    for (size_t m = block * kBlock; m < end; ++m) {
      const Eigen::Vector3d s = problem.points.row(members[m]);
      double best = kInf;
      for (size_t j = 0; j < spheres.size(); ++j) {
        const double v = (s - spheres[j].center).norm() - spheres[j].depth;
        if (v < best) best = v, owner[m] = static_cast<int>(j);
      }
    }
  });
  return owner;
}

double objective(const std::vector<FittedSphere>& spheres) {
  double worst = 0, sum = 0;
  for (const auto& s : spheres) worst = std::max(worst, s.error), sum += s.error;
  return worst + sum / static_cast<double>(spheres.size());
}

/// Splits `members` by `owner` into the spheres' member lists; removes empty spheres.
void distribute(const std::vector<int>& members, const std::vector<int>& owner,
                std::vector<FittedSphere>& spheres) {
  for (auto& s : spheres) s.members.clear();
  for (size_t m = 0; m < members.size(); ++m)
    spheres[static_cast<size_t>(owner[m])].members.push_back(members[m]);
  spheres.erase(std::remove_if(spheres.begin(), spheres.end(),
                               [](const FittedSphere& s) { return s.members.empty(); }),
                spheres.end());
}

}  // namespace

FittedSphere fit_sphere(const ReductionProblem& problem, const std::vector<int>& members,
                        const FittedSphere* hint, const ReductionOptions& options,
                        const std::vector<Eigen::Vector3d>* extreme) {
  assert(!members.empty());
  FittedSphere out;
  out.tag = hint != nullptr ? hint->tag : -1;
  out.members = members;
  std::sort(out.members.begin(), out.members.end());
  const std::vector<Eigen::Vector3d> hull =
      extreme != nullptr ? *extreme : extreme_points(problem.points, members, true);
  double gmax = 0;
  for (int s : members) gmax = std::max(gmax, problem.gap[s]);

  Eigen::Vector3d ball_center;
  double ball_radius;
  if (hint != nullptr) {
    ball_center = hint->center, ball_radius = hint->radius;
  } else {
    ball_center = Eigen::Vector3d::Zero();
    for (const auto& p : hull) ball_center += p;
    ball_center /= static_cast<double>(hull.size());
    ball_radius = max_distance(hull, ball_center) + gmax;
  }
  std::vector<int> cands = problem.medial_grid.query_ball(ball_center, ball_radius);
  const size_t limit = static_cast<size_t>(std::max(1, options.max_candidates));
  const size_t stride = cands.size() > limit ? (cands.size() + limit - 1) / limit : 1;

  double best = kInf;
  int best_idx = -1;
  // A candidate is dropped as soon as one hull point shows that its cost
  // cannot beat the best so far (with a relative safety of 1e-9, so that the
  // same candidate wins as with the full maximum); the hull point that
  // dropped the last candidate is tried first.
  size_t lead = 0;
  for (size_t i = 0; i < cands.size(); i += stride) {
    const int m = cands[i];
    const Eigen::Vector3d c = problem.medial.centers.row(m);
    const double depth = problem.medial.radii[m];
    if (best < kInf) {
      const double cutoff = best + depth;
      const double limit2 = cutoff > 0 ? cutoff * cutoff * (1 + 1e-9) : 0.0;
      if ((hull[lead] - c).squaredNorm() > limit2) continue;
      bool dropped = false;
      for (size_t h = 0; h < hull.size(); ++h) {
        if ((hull[h] - c).squaredNorm() > limit2) {
          lead = h, dropped = true;
          break;
        }
      }
      if (dropped) continue;
    }
    const double cost = max_distance(hull, c) - depth;
    if (cost < best) best = cost, best_idx = m;
  }
  if (hint != nullptr && hint->depth > 0) {
    const double cost = max_distance(hull, hint->center) - hint->depth;
    if (cost <= best) best = cost, best_idx = -2;
  }
  if (best_idx >= 0) {
    out.center = problem.medial.centers.row(best_idx);
    out.depth = problem.medial.radii[best_idx];
  } else if (best_idx == -2) {
    out.center = hint->center;
    out.depth = hint->depth;
  } else {
    out.center = ball_center;
    out.depth = 0;
  }
  refit_radius(problem, out);
  return out;
}

std::vector<Eigen::Vector3d> member_extreme_points(const ReductionProblem& problem,
                                                   const std::vector<int>& members) {
  assert(!members.empty());
  return extreme_points(problem.points, members, true);
}

std::vector<Eigen::Vector3d> union_extreme_points(const ReductionProblem& problem,
                                                  const std::vector<int>& members,
                                                  const std::vector<Eigen::Vector3d>& a,
                                                  const std::vector<Eigen::Vector3d>& b) {
  assert(!members.empty());
  // Small or degenerate unions: member_extreme_points keeps every member.
  if (members.size() <= 64) return extreme_points(problem.points, members, true);
  std::vector<Point> in;
  in.reserve(a.size() + b.size());
  for (const auto* set : {&a, &b})
    for (const auto& p : *set) in.emplace_back(p.x(), p.y(), p.z());
  std::vector<Point> hull;
  CGAL::extreme_points_3(in, std::back_inserter(hull));
  if (hull.empty()) return extreme_points(problem.points, members, true);
  std::vector<Eigen::Vector3d> out;
  out.reserve(hull.size());
  for (const Point& p : hull) out.emplace_back(p.x(), p.y(), p.z());
  return out;
}

void polish_sphere(const ReductionProblem& problem, const MeshOracle& oracle, FittedSphere& sphere,
                   int max_evaluations) {
  if (sphere.members.empty()) return;
  // Large member sets: the search runs on their extreme points along 162
  // directions (a slight underestimate of the farthest distance); the result
  // is refitted exactly and kept only when it beats the exact starting point.
  const std::vector<Eigen::Vector3d> hull =
      sphere.members.size() > 20000 ? support_points(problem.points, sphere.members)
                                    : extreme_points(problem.points, sphere.members, false);
  FittedSphere start = sphere;
  refit_radius(problem, start);
  double gmax = 0;
  for (int s : sphere.members) gmax = std::max(gmax, problem.gap[s]);
  auto cost = [&](const Eigen::Vector3d& c, double depth) {
    return max_distance(hull, c) + gmax - depth;
  };
  Eigen::Vector3d center = sphere.center;
  double depth = oracle.inside(center) ? oracle.distance(center) : 0.0;
  double best = cost(center, depth);
  double step = 0.25 * sphere.radius;
  const double min_step = 1e-3 * sphere.radius;
  int evaluations = 0;
  while (step > min_step && evaluations < max_evaluations) {
    bool improved = false;
    for (int axis = 0; axis < 3 && !improved; ++axis) {
      for (int sign = -1; sign <= 1 && !improved; sign += 2) {
        Eigen::Vector3d trial = center;
        trial[axis] += sign * step;
        ++evaluations;
        // Cheap lower bound first: the depth cannot exceed the old one by more than the step.
        if (max_distance(hull, trial) + gmax - (depth + step) >= best) continue;
        if (!oracle.inside(trial)) continue;
        const double d = oracle.distance(trial);
        const double c = cost(trial, d);
        if (c < best) best = c, center = trial, depth = d, improved = true;
      }
    }
    if (!improved) step *= 0.5;
  }
  sphere.center = center;
  sphere.depth = depth;
  refit_radius(problem, sphere);
  if (sphere.error > start.error) sphere = std::move(start);
}

namespace {

/// assign_and_refit() on `threads` workers.
void assign_and_refit_on(const ReductionProblem& problem, const std::vector<int>& members,
                         std::vector<FittedSphere>& spheres, int threads) {
  if (spheres.empty()) return;
  const std::vector<int> owner = assign(problem, members, spheres, threads);
  distribute(members, owner, spheres);
  parallel_for(spheres.size(), threads, [&](size_t j, int) { refit_radius(problem, spheres[j]); });
}

}  // namespace

void assign_and_refit(const ReductionProblem& problem, const std::vector<int>& members,
                      std::vector<FittedSphere>& spheres) {
  assign_and_refit_on(problem, members, spheres, 1);
}

void refine_jointly(const ReductionProblem& problem, std::vector<FittedSphere>& spheres,
                    const ReductionOptions& options) {
  std::vector<int> members;
  for (const auto& s : spheres) members.insert(members.end(), s.members.begin(), s.members.end());
  std::sort(members.begin(), members.end());
  if (members.empty()) return;
  auto score = [](const std::vector<FittedSphere>& set) {
    double worst = 0, sum = 0;
    int used = 0;
    for (const auto& s : set) {
      if (s.members.empty()) continue;
      worst = std::max(worst, s.error), sum += s.error, ++used;
    }
    return worst + sum / std::max(used, 1);
  };
  std::vector<FittedSphere> best = spheres;
  double best_score = score(spheres);
  for (int it = 0; it < options.lloyd_iterations; ++it) {
    if (CpuClock::now() > options.deadline) break;
    const std::vector<int> owner = assign(problem, members, spheres);
    for (auto& s : spheres) s.members.clear();
    for (size_t m = 0; m < members.size(); ++m)
      spheres[static_cast<size_t>(owner[m])].members.push_back(members[m]);
    for (auto& s : spheres) {
      if (s.members.empty()) continue;
      const FittedSphere hint = s;
      s = fit_sphere(problem, s.members, &hint, options);
    }
    const double sc = score(spheres);
    if (sc < best_score) best_score = sc, best = spheres;
  }
  spheres = best;
}

std::vector<std::vector<FittedSphere>> reduce_to_spheres(const ReductionProblem& problem,
                                                         const std::vector<int>& members, int max_k,
                                                         const ReductionOptions& options) {
  if (max_k < 1)
    throw ParameterError("reduce_to_spheres: max_k must be >= 1, got " + std::to_string(max_k));
  if (members.empty()) throw ParameterError("reduce_to_spheres: no samples to cover");
  std::vector<std::vector<FittedSphere>> result;
  std::vector<FittedSphere> spheres{fit_sphere(problem, members, nullptr, options)};
  result.push_back(spheres);

  if (options.threads < 1)
    throw ParameterError("ReductionOptions::threads must be >= 1, got " +
                         std::to_string(options.threads));
  const int threads = options.threads;
  for (int k = 2; k <= max_k; ++k) {
    // Seed: the sample whose assignment cost (error it causes) is largest.
    const std::vector<int> owner = assign(problem, members, spheres, threads);
    double worst = -kInf;
    size_t worst_m = 0;
    for (size_t m = 0; m < members.size(); ++m) {
      const auto& sp = spheres[static_cast<size_t>(owner[m])];
      const int s = members[m];
      const double v =
          (problem.points.row(s).transpose() - sp.center).norm() - sp.depth + problem.gap[s];
      if (v > worst) worst = v, worst_m = m;
    }
    const Eigen::Vector3d seed = problem.points.row(members[worst_m]);
    const double search = std::max(spheres[static_cast<size_t>(owner[worst_m])].radius, 1e-12);
    const std::vector<int> cands = problem.medial_grid.query_ball(seed, search);
    double best = kInf;
    int best_idx = -1;
    for (int m : cands) {
      const Eigen::Vector3d c = problem.medial.centers.row(m);
      const double depth = problem.medial.radii[m];
      const double v = (seed - c).norm() - depth - options.depth_bias * depth;
      if (v < best) best = v, best_idx = m;
    }
    if (best_idx < 0) break;  // nothing to add: keep fewer spheres
    FittedSphere added;
    added.center = problem.medial.centers.row(best_idx);
    added.depth = problem.medial.radii[best_idx];
    added.radius = search;
    spheres.push_back(added);
    assign_and_refit_on(problem, members, spheres, threads);

    std::vector<FittedSphere> best_config = spheres;
    double best_obj = objective(spheres);
    for (int it = 0; it < options.lloyd_iterations; ++it) {
      if (CpuClock::now() > options.deadline) break;
      parallel_for(spheres.size(), threads, [&](size_t j, int) {
        const FittedSphere hint = spheres[j];
        spheres[j] = fit_sphere(problem, hint.members, &hint, options);
      });
      std::vector<std::vector<int>> before;
      for (const auto& s : spheres) before.push_back(s.members);
      assign_and_refit_on(problem, members, spheres, threads);
      const double obj = objective(spheres);
      if (obj < best_obj) best_obj = obj, best_config = spheres;
      bool stable = spheres.size() == before.size();
      for (size_t j = 0; stable && j < spheres.size(); ++j)
        stable = spheres[j].members == before[j];
      if (stable) break;
    }
    spheres = best_config;
    result.push_back(spheres);
  }
  while (static_cast<int>(result.size()) < max_k) result.push_back(result.back());
  return result;
}

}  // namespace icd::mesh
