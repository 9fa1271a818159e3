#include <icd/mesh/spheres/worst_split.hpp>

#include <algorithm>
#include <cassert>
#include <iterator>
#include <limits>
#include <optional>
#include <string>
#include <utility>

#include <Eigen/Eigenvalues>

#include <icd/mesh/core/error.hpp>
#include <icd/mesh/spheres/exchange.hpp>
#include <icd/mesh/spheres/parallel.hpp>

namespace icd::mesh {
namespace {

void check_arguments(const WorstSplitOptions& o, int cap, int branching) {
  if (o.measure_directions < 1 || o.choice_directions < 1 || o.max_tries < 0 ||
      !(o.relief_fraction >= 0) || !(o.mean_rise_limit >= 0))
    throw ParameterError(
        "WorstSplitOptions: measure_directions and choice_directions must be >= 1, max_tries >= 0 "
        "and relief_fraction, mean_rise_limit >= 0");
  if (cap < 0 || branching < 2)
    throw ParameterError("split_worst_leaves: cap must be >= 0 and branching >= 2, got " +
                         std::to_string(cap) + " and " + std::to_string(branching));
}

/// The two halves of a leaf, fitted and polished, with their medial samples
/// and true errors; empty when the leaf does not split in two non-empty halves.
struct Halves {
  std::vector<FittedSphere> spheres;
  std::vector<std::vector<int>> medial;
  double error[2] = {0, 0};
};

/// Two spheres dividing the leaf's coverage samples, starting from the
/// centres of `seeds`: samples assigned (assign_and_refit), centres
/// polished for the bound, reassigned, boundary exchange. Empty when a half
/// loses all its samples.
std::vector<FittedSphere> settle(const ReductionProblem& dense, const MeshOracle& oracle,
                                 const FittedSphere& leaf, std::vector<FittedSphere> halves) {
  assign_and_refit(dense, leaf.members, halves);
  for (auto& h : halves) polish_sphere(dense, oracle, h);
  assign_and_refit(dense, leaf.members, halves);
  if (halves.size() < 2) return {};
  shrink_by_exchange(dense, halves);
  return halves;
}

/// The principal axes of a leaf's coverage samples (columns, increasing
/// spread).
Eigen::Matrix3d principal_axes(const ReductionProblem& dense, const FittedSphere& leaf) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (int m : leaf.members) mean += dense.points.row(m).transpose();
  mean /= static_cast<double>(leaf.members.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (int m : leaf.members) {
    const Eigen::Vector3d d = dense.points.row(m).transpose() - mean;
    cov += d * d.transpose();
  }
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvectors();
}

/// The candidate two-sphere divisions of a leaf, numbered 0 to
/// kNumCandidates - 1: the two-sphere reduction of its medial samples (0),
/// and the median planes of its coverage samples across its two principal
/// axes of largest spread (1, 2; each side fitted with fit_sphere). Settled
/// (see settle); empty when that candidate does not divide the leaf in two.
constexpr int kNumCandidates = 3;

std::vector<FittedSphere> candidate(int k, const ReductionProblem& coarse,
                                    const ReductionProblem& dense, const MeshOracle& oracle,
                                    const ReductionOptions& reduction, const FittedSphere& leaf,
                                    const std::vector<int>& leaf_medial,
                                    const Eigen::Matrix3d& axes) {
  if (k == 0) {
    if (leaf_medial.size() < 2) return {};
    std::vector<FittedSphere> h = reduce_to_spheres(coarse, leaf_medial, 2, reduction)[1];
    if (h.size() != 2) return {};
    return settle(dense, oracle, leaf, std::move(h));
  }
  const Eigen::Vector3d n = axes.col(3 - k);  // k = 1: largest spread
  std::vector<double> projection(leaf.members.size());
  for (size_t i = 0; i < leaf.members.size(); ++i)
    projection[i] = n.dot(dense.points.row(leaf.members[i]).transpose());
  std::vector<double> sorted = projection;
  const auto mid = sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2);
  std::nth_element(sorted.begin(), mid, sorted.end());
  const double median = *mid;
  std::vector<int> side[2];
  for (size_t i = 0; i < leaf.members.size(); ++i)
    side[projection[i] < median ? 0 : 1].push_back(leaf.members[i]);
  if (side[0].empty() || side[1].empty()) return {};
  std::vector<FittedSphere> h;
  for (const auto& members : side) h.push_back(fit_sphere(dense, members, nullptr, reduction));
  return settle(dense, oracle, leaf, std::move(h));
}

/// The candidate division whose larger true error is smallest, both halves
/// moved by polish_protrusion first (the candidates are computed in
/// parallel, one per task, worker w querying oracles[w]; the choice does
/// not depend on the number of workers); the leaf's medial samples are
/// divided by the assignment rule (so that each half can be split again).
Halves split_in_two(const ReductionProblem& coarse, const ReductionProblem& dense,
                    const std::vector<const MeshOracle*>& oracles,
                    const ReductionOptions& reduction, const FittedSphere& leaf,
                    const std::vector<int>& leaf_medial, unsigned seed,
                    const ProtrusionPolishOptions& polish, const MatX3d& choice,
                    const MatX3d& directions) {
  Halves out;
  if (leaf.members.size() < 2) return out;
  const MeshOracle& oracle = *oracles.front();
  const Eigen::Matrix3d axes = principal_axes(dense, leaf);
  struct Tried {
    std::vector<FittedSphere> halves;
    double error[2] = {0, 0};
  };
  std::vector<Tried> tried(kNumCandidates);
  parallel_for(tried.size(), static_cast<int>(oracles.size()), [&](size_t k, int worker) {
    const MeshOracle& o = *oracles[static_cast<size_t>(worker)];
    Tried& t = tried[k];
    t.halves = candidate(static_cast<int>(k), coarse, dense, o, reduction, leaf, leaf_medial, axes);
    if (t.halves.size() != 2) return;
    for (size_t h = 0; h < 2; ++h) {
      polish_protrusion(dense, o, t.halves[h], seed + static_cast<unsigned>(h), polish);
      t.error[h] = sphere_protrusion(o, t.halves[h].center, t.halves[h].radius, choice);
    }
  });
  double best = std::numeric_limits<double>::infinity();
  for (Tried& t : tried) {
    if (t.halves.size() != 2) continue;
    const double worst = std::max(t.error[0], t.error[1]);
    if (!(worst < best)) continue;
    best = worst;
    out.spheres = std::move(t.halves);
    out.error[0] = t.error[0], out.error[1] = t.error[1];
  }
  if (out.spheres.size() != 2) return Halves{};
  for (size_t k = 0; k < 2; ++k)
    out.error[k] =
        sphere_protrusion(oracle, out.spheres[k].center, out.spheres[k].radius, directions);
  std::vector<FittedSphere> medial_split = out.spheres;
  for (auto& h : medial_split) h.tag = -1;
  medial_split[0].tag = 0, medial_split[1].tag = 1;
  out.medial.assign(2, {});
  if (!leaf_medial.empty()) {
    assign_and_refit(coarse, leaf_medial, medial_split);
    for (const auto& h : medial_split) out.medial[static_cast<size_t>(h.tag)] = h.members;
  }
  for (size_t k = 0; k < 2; ++k) {
    if (out.medial[k].empty()) out.medial[k] = leaf_medial;  // keep the half placeable
    out.spheres[k].tag = leaf.tag;
  }
  return out;
}

/// Sorted union of two index lists (a linear merge when both are sorted).
std::vector<int> merged(const std::vector<int>& a, const std::vector<int>& b) {
  std::vector<int> out;
  out.reserve(a.size() + b.size());
  if (std::is_sorted(a.begin(), a.end()) && std::is_sorted(b.begin(), b.end())) {
    std::merge(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(out));
  } else {
    out = a;
    out.insert(out.end(), b.begin(), b.end());
    std::sort(out.begin(), out.end());
  }
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

/// Two siblings replaced by one sphere (fitted to the union of their samples,
/// centre polished for the bound and then for the true error).
struct Merge {
  size_t first = 0, second = 0;  // the merged leaves (first < second)
  FittedSphere sphere;
  std::vector<int> medial;
  double error = 0;  // true error of the merged sphere
};

}  // namespace

WorstSplitResult split_worst_leaves(const ReductionProblem& coarse, const ReductionProblem& dense,
                                    const std::vector<const MeshOracle*>& oracles,
                                    const ReductionOptions& reduction, LeafLevel& level, int cap,
                                    int branching, const WorstSplitOptions& options) {
  check_arguments(options, cap, branching);
  if (oracles.empty() || std::find(oracles.begin(), oracles.end(), nullptr) != oracles.end())
    throw ParameterError("split_worst_leaves: needs at least one oracle, none null");
  const MeshOracle& oracle = *oracles.front();
  const int workers = static_cast<int>(oracles.size());
  assert(level.spheres.size() == level.medial.size() &&
         level.spheres.size() == level.parent.size());
  const MatX3d directions = spiral_directions(options.measure_directions);
  const MatX3d choice = spiral_directions(options.choice_directions);
  WorstSplitResult result;
  // value[i]: the true error when exact[i], else an upper bound of it (the
  // error bound radius - depth, which no point of the sphere exceeds when the
  // centre is inside; a centre outside has depth 0, bound = radius).
  std::vector<double> value;
  std::vector<char> exact, done;
  for (const auto& s : level.spheres) value.push_back(s.radius - s.depth);
  exact.assign(value.size(), 0);
  done.assign(value.size(), 0);
  // extreme[i]: member_extreme_points of leaf i once a merge search needed
  // them (empty until then); the pair fits of the merge search take their
  // union's from these instead of a hull of all members.
  std::vector<std::vector<Eigen::Vector3d>> extreme(value.size());
  auto extreme_of = [&](size_t i) -> const std::vector<Eigen::Vector3d>& {
    if (extreme[i].empty()) extreme[i] = member_extreme_points(dense, level.spheres[i].members);
    return extreme[i];
  };
  std::vector<int> children;
  for (int p : level.parent) {
    if (p >= static_cast<int>(children.size())) children.resize(static_cast<size_t>(p) + 1, 0);
    children[static_cast<size_t>(p)] += 1;
  }
  auto measure = [&](const FittedSphere& s) {
    ++result.measured;
    return sphere_protrusion(oracle, s.center, s.radius, directions);
  };
  // The largest value among the leaves with done unset, made exact.
  auto top = [&]() {
    for (;;) {
      int best = -1;
      for (size_t i = 0; i < value.size(); ++i) {
        if (done[i]) continue;
        if (best < 0 || value[i] > value[static_cast<size_t>(best)]) best = static_cast<int>(i);
      }
      if (best < 0 || exact[static_cast<size_t>(best)]) return best;
      value[static_cast<size_t>(best)] = measure(level.spheres[static_cast<size_t>(best)]);
      exact[static_cast<size_t>(best)] = 1;
    }
  };
  auto level_worst = [&]() {
    std::fill(done.begin(), done.end(), 0);
    const int w = top();
    return w < 0 ? 0.0 : value[static_cast<size_t>(w)];
  };
  result.worst_before = level_worst();
  // The level's mean true error at the start, on the choice directions (a
  // subset's worth of the measuring ones: slightly below the mean on those,
  // so the rule below errs on the side of not raising the mean).
  std::vector<double> start_error(level.spheres.size());
  parallel_for(start_error.size(), workers, [&](size_t i, int worker) {
    const FittedSphere& s = level.spheres[i];
    start_error[i] =
        sphere_protrusion(*oracles[static_cast<size_t>(worker)], s.center, s.radius, choice);
  });
  double mean_error = 0;
  for (double e : start_error) mean_error += e;  // in leaf order, as without workers
  mean_error /= static_cast<double>(std::max<size_t>(level.spheres.size(), 1));
  result.mean_before = mean_error;

  // The best merge of two siblings of leaf i (other than i), or none with an
  // error below `limit`: the pair whose fitted sphere has the lowest error
  // bound, polished and measured.
  auto best_merge = [&](size_t i, double limit) -> std::optional<Merge> {
    const int p = level.parent[i];
    size_t lo = i, hi = i + 1;
    while (lo > 0 && level.parent[lo - 1] == p) --lo;
    while (hi < level.parent.size() && level.parent[hi] == p) ++hi;
    std::optional<Merge> best;
    for (size_t j = lo; j < hi; ++j) {
      for (size_t k = j + 1; k < hi; ++k) {
        if (j == i || k == i) continue;
        const FittedSphere& a = level.spheres[j];
        const FittedSphere& b = level.spheres[k];
        if ((a.center - b.center).norm() > a.radius + b.radius) continue;
        const std::vector<int> members = merged(a.members, b.members);
        const std::vector<Eigen::Vector3d> hull =
            union_extreme_points(dense, members, extreme_of(j), extreme_of(k));
        FittedSphere fit = fit_sphere(dense, members, nullptr, reduction, &hull);
        if (!(fit.error < limit) && fit.radius >= limit) continue;
        if (!best || fit.error < best->sphere.error) {
          best = Merge{j, k, std::move(fit), {}, 0.0};
        }
      }
    }
    if (!best) return best;
    polish_sphere(dense, oracle, best->sphere);
    polish_protrusion(dense, oracle, best->sphere, 104729u * static_cast<unsigned>(i) + 3u,
                      options.polish);
    best->error = measure(best->sphere);
    if (!(best->error < limit)) return std::nullopt;
    best->medial = merged(level.medial[best->first], level.medial[best->second]);
    best->sphere.tag = level.spheres[best->first].tag;
    return best;
  };

  std::vector<char> tried(value.size(), 0);
  // Leaf `at` replaced by a sphere of measured true error `error`: untried again.
  auto replace_leaf = [&](size_t at, FittedSphere sphere, std::vector<int> medial, double error) {
    level.spheres[at] = std::move(sphere);
    level.medial[at] = std::move(medial);
    extreme[at].clear();
    value[at] = error;
    exact[at] = 1;
    tried[at] = 0;
  };
  const double relief_threshold = options.relief_fraction * result.worst_before;
  while (result.tries < options.max_tries && CpuClock::now() < options.deadline) {
    for (size_t i = 0; i < done.size(); ++i) done[i] = tried[i];
    const int pick = top();
    if (pick < 0) break;
    size_t i = static_cast<size_t>(pick);
    const double worst = value[i];
    tried[i] = 1;
    const int p = level.parent[i];
    const bool free_slot = static_cast<long long>(level.spheres.size()) < cap &&
                           children[static_cast<size_t>(p)] < branching;
    if (!free_slot) {
      if (children[static_cast<size_t>(p)] >= branching) ++result.blocked_by_parent;
      if (!(worst >= relief_threshold)) {
        if (static_cast<long long>(level.spheres.size()) >= cap) break;  // nothing left to gain
        continue;
      }
    }
    ++result.tries;
    Halves halves =
        split_in_two(coarse, dense, oracles, reduction, level.spheres[i], level.medial[i],
                     7919u * static_cast<unsigned>(i) + 17u, options.polish, choice, directions);
    const bool relief = worst >= relief_threshold;
    if (halves.spheres.size() != 2) {
      if (relief) ++result.relief_no_split;  // a relief try without a split
      continue;
    }
    result.measured += 2;
    const double e0 = halves.error[0];
    const double e1 = halves.error[1];
    if (!(e0 < worst && e1 < worst)) {
      if (relief) ++result.relief_no_split;  // a relief try without a split
      continue;
    }
    // Below the relief band the level's mean error must not rise:
    // e0 + e1 - E <= mean (the mean true error at the start).
    if (!relief && e0 + e1 - worst > options.mean_rise_limit * mean_error) continue;
    if (!free_slot) {
      std::optional<Merge> merge = best_merge(i, worst);
      if (!merge) {
        if (relief) ++result.relief_no_merge;  // ... or without room
        continue;
      }
      for (size_t j : {merge->first, merge->second}) {
        if (!exact[j]) value[j] = measure(level.spheres[j]), exact[j] = 1;
      }
      const double rise = merge->error - value[merge->first] - value[merge->second];
      if (!relief && e0 + e1 - worst + rise > options.mean_rise_limit * mean_error) continue;
      // The merged sphere replaces the first of the pair, the second goes.
      replace_leaf(merge->first, std::move(merge->sphere), std::move(merge->medial), merge->error);
      const auto gone = static_cast<std::ptrdiff_t>(merge->second);
      level.spheres.erase(level.spheres.begin() + gone);
      level.medial.erase(level.medial.begin() + gone);
      level.parent.erase(level.parent.begin() + gone);
      extreme.erase(extreme.begin() + gone);
      value.erase(value.begin() + gone);
      exact.erase(exact.begin() + gone);
      done.erase(done.begin() + gone);
      tried.erase(tried.begin() + gone);
      if (merge->second < i) --i;
      children[static_cast<size_t>(p)] -= 1;
      ++result.merges;
    }
    replace_leaf(i, std::move(halves.spheres[0]), std::move(halves.medial[0]), e0);
    const auto at = static_cast<std::ptrdiff_t>(i) + 1;
    level.spheres.insert(level.spheres.begin() + at, std::move(halves.spheres[1]));
    level.medial.insert(level.medial.begin() + at, std::move(halves.medial[1]));
    level.parent.insert(level.parent.begin() + at, p);
    extreme.insert(extreme.begin() + at, std::vector<Eigen::Vector3d>{});
    value.insert(value.begin() + at, e1);
    exact.insert(exact.begin() + at, 1);
    done.insert(done.begin() + at, 0);
    tried.insert(tried.begin() + at, 0);
    children[static_cast<size_t>(p)] += 1;
    ++result.splits;
  }
  result.worst_after = level_worst();
  return result;
}

}  // namespace icd::mesh
