#include "fem/lane_loops.hpp"

#include <algorithm>
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

template <MaterialModel kModel, bool kHealth>
[[gnu::always_inline]] inline void force_body(const LaneLoopInput& in, int begin, int end,
                                              LaneRangeHealth* health) {
  // Health in lane-wise accumulators (vectorised): energy partial sums,
  // smallest det F and its element; merged in lane order at the end.
  double lane_sum[kLanes] = {}, lane_min[kLanes], lane_arg[kLanes];
  for (int l = 0; l < kLanes; ++l) {
    lane_min[l] = std::numeric_limits<double>::infinity();
    lane_arg[l] = -1;
  }
  for (int e0 = begin; e0 < end; e0 += kLanes) {
    const int count = end - e0 < kLanes ? end - e0 : kLanes;
    const Block& block = in.blocks[e0 / kLanes];
    double out[kLanes][12];
    double psi[kLanes], det[kLanes];
    block_forces<kModel, kHealth>(in.x, in.tets + 4 * e0, count, block, in.mu, in.lambda, out, psi,
                                  det);
    if constexpr (kHealth) {
      for (int l = 0; l < kLanes; ++l) {  // padding lanes: volume 0, det F = 0 ignored
        const bool valid = l < count;
        lane_sum[l] += valid ? block.volume[l] * psi[l] : 0.0;
        const bool lower = valid && det[l] < lane_min[l];
        lane_min[l] = lower ? det[l] : lane_min[l];
        lane_arg[l] = lower ? static_cast<double>(e0 + l) : lane_arg[l];
      }
    }
    for (int l = 0; l < count; ++l) scatter(in, e0 + l, out[l]);
  }
  if constexpr (kHealth) {
    LaneRangeHealth h;
    h.min_det = std::numeric_limits<double>::infinity();
    for (int l = 0; l < kLanes; ++l) {
      h.energy += lane_sum[l];
      if (lane_arg[l] >= 0 &&
          (lane_min[l] < h.min_det || (lane_min[l] == h.min_det && lane_arg[l] < h.min_element))) {
        h.min_det = lane_min[l];
        h.min_element = static_cast<int>(lane_arg[l]);
      }
    }
    *health = h;
  }
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

template <MaterialModel kModel, bool kHealth>
void force_baseline(const LaneLoopInput& in, int begin, int end, LaneRangeHealth* health) {
  force_body<kModel, kHealth>(in, begin, end, health);
}
template <MaterialModel kModel>
void differential_baseline(const LaneLoopInput& in, const double* dx, int begin, int end) {
  differential_body<kModel>(in, dx, begin, end);
}

#if ICD_FEM_HAVE_AVX2_LOOPS
template <MaterialModel kModel, bool kHealth>
__attribute__((target("avx2"))) void force_avx2(const LaneLoopInput& in, int begin, int end,
                                                LaneRangeHealth* health) {
  force_body<kModel, kHealth>(in, begin, end, health);
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

template <MaterialModel kModel, bool kHealth>
void force_range(const LaneLoopInput& in, int begin, int end, LaneRangeHealth* health) {
#if ICD_FEM_HAVE_AVX2_LOOPS
  if (g_isa == LaneIsa::AVX2) return force_avx2<kModel, kHealth>(in, begin, end, health);
#endif
  force_baseline<kModel, kHealth>(in, begin, end, health);
}

template <MaterialModel kModel>
void differential_range(const LaneLoopInput& in, const double* dx, int begin, int end) {
#if ICD_FEM_HAVE_AVX2_LOOPS
  if (g_isa == LaneIsa::AVX2) return differential_avx2<kModel>(in, dx, begin, end);
#endif
  differential_baseline<kModel>(in, dx, begin, end);
}

#define ICD_FEM_LANE_INSTANTIATE(M)                                                  \
  template void force_range<MaterialModel::M, false>(const LaneLoopInput&, int, int, \
                                                     LaneRangeHealth*);              \
  template void force_range<MaterialModel::M, true>(const LaneLoopInput&, int, int,  \
                                                    LaneRangeHealth*);               \
  template void differential_range<MaterialModel::M>(const LaneLoopInput&, const double*, int, int);
ICD_FEM_LANE_INSTANTIATE(Linear)
ICD_FEM_LANE_INSTANTIATE(StVK)
ICD_FEM_LANE_INSTANTIATE(StableNeoHookean)
#undef ICD_FEM_LANE_INSTANTIATE

}  // namespace icd::fem::lanes
