#include <icd/fem/lane_loops.hpp>

#include <algorithm>
#include <cstring>
#include <limits>

namespace icd::fem::lanes {
namespace {

#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
#define ICD_FEM_HAVE_AVX2_LOOPS 1
#else
#define ICD_FEM_HAVE_AVX2_LOOPS 0
#endif

bool cpu_has_avx2() {
#if ICD_FEM_HAVE_AVX2_LOOPS
  __builtin_cpu_init();  // g_isa is initialised by a static constructor, maybe before libgcc's
  return __builtin_cpu_supports("avx2");
#else
  return false;
#endif
}

// Zero (Baseline) until this initialiser has run: a safe default for any earlier caller.
LaneIsa g_isa = cpu_has_avx2() ? LaneIsa::AVX2 : LaneIsa::Baseline;

// Scatter of one element's 12 nodal forces (element order: deterministic sums).
[[gnu::always_inline]] inline void scatter(const LaneLoopInput& in, int e, const double* out) {
  if (!in.forces) {
    double* dst = in.element_forces + 12 * static_cast<long>(e);
    for (int k = 0; k < 12; ++k) dst[k] = out[k];
    return;
  }
  const int* t = in.tets + 4 * e;
  for (int a = 0; a < 4; ++a) {
    double* fa = in.forces + 3 * t[a];
    fa[0] += out[3 * a];
    fa[1] += out[3 * a + 1];
    fa[2] += out[3 * a + 2];
  }
}

// Health of a range of elements in lane-wise accumulators: energy partial
// sums, smallest det F and its element per lane, merged in lane order at the
// end. GCC vector types of 2 doubles (one SSE2 register, the baseline
// x86-64 width) make the per-block update compare + select instructions in
// both builds; written as a plain loop with a select, GCC turned the select
// into a conditional store and emitted 8 scalar branches per block.
struct LaneHealth {
  typedef double Vec2 __attribute__((vector_size(16)));
  static constexpr int kVectors = kLanes / 2;
  static constexpr double kInf = std::numeric_limits<double>::infinity();
  Vec2 sum[kVectors], min[kVectors], arg[kVectors];  // arg: element index as a double, -1: none

  LaneHealth() {
    for (int k = 0; k < kVectors; ++k) {
      sum[k] = Vec2{0.0, 0.0};
      min[k] = Vec2{kInf, kInf};
      arg[k] = Vec2{-1.0, -1.0};
    }
  }
  // A full block of 8 elements starting at e0: no per-lane condition.
  [[gnu::always_inline]] void add_full(int e0, const double* volume, const double* psi,
                                       const double* det) {
    const double b = static_cast<double>(e0);
    for (int k = 0; k < kVectors; ++k) {
      Vec2 v, p, d;
      std::memcpy(&v, volume + 2 * k, sizeof v);
      std::memcpy(&p, psi + 2 * k, sizeof p);
      std::memcpy(&d, det + 2 * k, sizeof d);
      const Vec2 index{b + 2 * k, b + 2 * k + 1};
      sum[k] += v * p;
      const auto lower = d < min[k];
      min[k] = lower ? d : min[k];
      arg[k] = lower ? index : arg[k];
    }
  }
  // The first `count` lanes of a block (padding lanes: volume 0, det F = 0, ignored).
  void add_partial(int e0, int count, const double* volume, const double* psi, const double* det) {
    for (int l = 0; l < count; ++l) {
      sum[l / 2][l % 2] += volume[l] * psi[l];
      if (det[l] < min[l / 2][l % 2]) {
        min[l / 2][l % 2] = det[l];
        arg[l / 2][l % 2] = static_cast<double>(e0 + l);
      }
    }
  }
  LaneRangeHealth result() const {
    LaneRangeHealth h;
    h.min_det = kInf;
    for (int l = 0; l < kLanes; ++l) {
      const double lane_min = min[l / 2][l % 2], lane_arg = arg[l / 2][l % 2];
      h.energy += sum[l / 2][l % 2];
      if (lane_arg >= 0 &&
          (lane_min < h.min_det || (lane_min == h.min_det && lane_arg < h.min_element))) {
        h.min_det = lane_min;
        h.min_element = static_cast<int>(lane_arg);
      }
    }
    return h;
  }
};

// The orientation test of a range of elements: per lane, a mask that stays
// all ones while every det F seen is > 0 (a compare and an AND per block, no
// branch, no minimum, no element index; NaN compares false).
struct LaneOrientation {
  typedef double Vec2 __attribute__((vector_size(16)));
  typedef long long Mask2 __attribute__((vector_size(16)));
  static constexpr int kVectors = kLanes / 2;
  Mask2 ok[kVectors];

  LaneOrientation() {
    for (int k = 0; k < kVectors; ++k) ok[k] = Mask2{-1, -1};
  }
  [[gnu::always_inline]] void add_full(const double* det) {
    const Vec2 zero{0.0, 0.0};
    for (int k = 0; k < kVectors; ++k) {
      Vec2 d;
      std::memcpy(&d, det + 2 * k, sizeof d);
      ok[k] &= d > zero;
    }
  }
  // The first `count` lanes of a block (padding lanes have det F = 0).
  void add_partial(int count, const double* det) {
    for (int l = 0; l < count; ++l)
      if (!(det[l] > 0.0)) ok[l / 2][l % 2] = 0;
  }
  bool result() const {
    bool all = true;
    for (int k = 0; k < kVectors; ++k) all = all && ok[k][0] != 0 && ok[k][1] != 0;
    return all;
  }
};

template <MaterialModel kModel, LaneCheck kCheck>
[[gnu::always_inline]] inline void force_body(const LaneLoopInput& in, int begin, int end,
                                              LaneRangeHealth* health) {
  LaneHealth lane_health;
  LaneOrientation lane_orientation;
  for (int e0 = begin; e0 < end; e0 += kLanes) {
    const int count = end - e0 < kLanes ? end - e0 : kLanes;
    const Block& block = in.blocks[e0 / kLanes];
    double out[kLanes][12];
    double psi[kLanes], det[kLanes];
    block_forces<kModel, kCheck>(in.x, in.tets + 4 * e0, count, block, in.mu, in.lambda, out, psi,
                                 det);
    if constexpr (kCheck == LaneCheck::Full) {
      if (count == kLanes)
        lane_health.add_full(e0, block.volume, psi, det);
      else
        lane_health.add_partial(e0, count, block.volume, psi, det);
    } else if constexpr (kCheck == LaneCheck::Orientation) {
      if (count == kLanes)
        lane_orientation.add_full(det);
      else
        lane_orientation.add_partial(count, det);
    }
    for (int l = 0; l < count; ++l) scatter(in, e0 + l, out[l]);
  }
  if constexpr (kCheck == LaneCheck::Full) *health = lane_health.result();
  if constexpr (kCheck == LaneCheck::Orientation) health->oriented = lane_orientation.result();
}

template <MaterialModel kModel>
[[gnu::always_inline]] inline void differential_body(const LaneLoopInput& in, const double* dx,
                                                     int begin, int end) {
  for (int e0 = begin; e0 < end; e0 += kLanes) {
    const int count = end - e0 < kLanes ? end - e0 : kLanes;
    double out[kLanes][12];
    block_differential<kModel>(in.x, dx, in.tets + 4 * e0, count, in.blocks[e0 / kLanes], in.mu,
                               in.lambda, out);
    for (int l = 0; l < count; ++l) scatter(in, e0 + l, out[l]);
  }
}

template <MaterialModel kModel, LaneCheck kCheck>
void force_baseline(const LaneLoopInput& in, int begin, int end, LaneRangeHealth* health) {
  force_body<kModel, kCheck>(in, begin, end, health);
}
template <MaterialModel kModel>
void differential_baseline(const LaneLoopInput& in, const double* dx, int begin, int end) {
  differential_body<kModel>(in, dx, begin, end);
}

#if ICD_FEM_HAVE_AVX2_LOOPS
template <MaterialModel kModel, LaneCheck kCheck>
__attribute__((target("avx2"))) void force_avx2(const LaneLoopInput& in, int begin, int end,
                                                LaneRangeHealth* health) {
  force_body<kModel, kCheck>(in, begin, end, health);
}
template <MaterialModel kModel>
__attribute__((target("avx2"))) void differential_avx2(const LaneLoopInput& in, const double* dx,
                                                       int begin, int end) {
  differential_body<kModel>(in, dx, begin, end);
}
#endif

}  // namespace

LaneIsa lane_isa() { return g_isa; }

bool set_lane_isa(LaneIsa isa) {
  if (isa == LaneIsa::AVX2 && !cpu_has_avx2()) return false;
  g_isa = isa;
  return true;
}

const char* to_string(LaneIsa isa) { return isa == LaneIsa::AVX2 ? "avx2" : "baseline"; }

template <MaterialModel kModel, LaneCheck kCheck>
void force_range(const LaneLoopInput& in, int begin, int end, LaneRangeHealth* health) {
#if ICD_FEM_HAVE_AVX2_LOOPS
  if (g_isa == LaneIsa::AVX2) return force_avx2<kModel, kCheck>(in, begin, end, health);
#endif
  force_baseline<kModel, kCheck>(in, begin, end, health);
}

template <MaterialModel kModel>
void differential_range(const LaneLoopInput& in, const double* dx, int begin, int end) {
#if ICD_FEM_HAVE_AVX2_LOOPS
  if (g_isa == LaneIsa::AVX2) return differential_avx2<kModel>(in, dx, begin, end);
#endif
  differential_baseline<kModel>(in, dx, begin, end);
}

#define ICD_FEM_LANE_INSTANTIATE(M)                                                              \
  template void force_range<MaterialModel::M, LaneCheck::None>(const LaneLoopInput&, int, int,   \
                                                               LaneRangeHealth*);                \
  template void force_range<MaterialModel::M, LaneCheck::Full>(const LaneLoopInput&, int, int,   \
                                                               LaneRangeHealth*);                \
  template void force_range<MaterialModel::M, LaneCheck::Orientation>(const LaneLoopInput&, int, \
                                                                      int, LaneRangeHealth*);    \
  template void differential_range<MaterialModel::M>(const LaneLoopInput&, const double*, int, int);
ICD_FEM_LANE_INSTANTIATE(Linear)
ICD_FEM_LANE_INSTANTIATE(StVK)
ICD_FEM_LANE_INSTANTIATE(StableNeoHookean)
#undef ICD_FEM_LANE_INSTANTIATE

}  // namespace icd::fem::lanes
