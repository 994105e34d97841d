#include "Drr/SiddonPacketKernel.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define FCT_PACKET_KERNEL_X86 1
#include <immintrin.h>
#endif

namespace fct {

bool SiddonPacketKernel::available() {
#if defined(FCT_PACKET_KERNEL_X86)
  static const bool supported = __builtin_cpu_supports("avx512f");
  return supported;
#else
  return false;
#endif
}

#if defined(FCT_PACKET_KERNEL_X86)

// GCC 12 reports its own AVX-512 headers' _mm512_undefined_* values as maybe-uninitialized (a known false positive),
// and notes that AVX-512 arguments change the ABI, which does not matter for functions local to this file.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#pragma GCC diagnostic ignored "-Wpsabi"
#endif

namespace {

/// Float partial sums are added into double every this many columns of D, counted from column 0 (not from the
/// packet's first column), so that a lane's result does not depend on the packet it is in.
constexpr int kFlushColumns = 64;

/// How many columns ahead the walk prefetches its rows.
constexpr int kPrefetchColumns = 8;

/// 1 / slope, or 0 for a slope so small that the ray cannot cross a boundary of that axis within a column.
float inverseSlope(double perU) { return std::abs(perU) > 1e-30 ? static_cast<float>(1.0 / perU) : 0.0f; }

#define FCT_AVX512 __attribute__((target("avx512f")))

/// Cell index along an axis at the points u: floor(start + slope·u) clamped to [0, last] (grid coordinates are >= 0
/// on the clipped ray, so truncation is floor).
FCT_AVX512 inline __m512i cellAt(__m512 u, __m512 slope, __m512 start, __m512i last) {
  return _mm512_min_epi32(_mm512_max_epi32(_mm512_cvttps_epi32(_mm512_fmadd_ps(slope, u, start)), _mm512_setzero_si512()),
                          last);
}

/// Each lane's voxel at window position `index` of row 0 (low0, high0) or, where `upper` is set, of row 1.
FCT_AVX512 inline __m512 pick(__m512 low0, __m512 high0, __m512 low1, __m512 high1, __m512i index, __mmask16 upper) {
  return _mm512_mask_blend_ps(upper, _mm512_permutex2var_ps(low0, index, high0),
                              _mm512_permutex2var_ps(low1, index, high1));
}

/// Lane `lane` of v.
FCT_AVX512 inline int laneValue(__m512i v, int lane) {
  return _mm_cvtsi128_si32(_mm512_castsi512_si128(_mm512_permutexvar_epi32(_mm512_set1_epi32(lane), v)));
}

/// True when every lane of `lanes` has its H cells in [start, start + kWindow) and its V cells in {vMin, vMin + 1}.
FCT_AVX512 inline bool fitsWindow(__mmask16 lanes, __m512i hA, __m512i hB, __m512i vA, __m512i vB, int start,
                                  int vMin) {
  const __m512i windowLast = _mm512_set1_epi32(SiddonPacketKernel::kWindow - 1), one = _mm512_set1_epi32(1);
  const __m512i offset = _mm512_set1_epi32(start), row = _mm512_set1_epi32(vMin);
  // Unsigned comparisons: a cell below start or vMin wraps around to a large number.
  const __mmask16 outside = _mm512_mask_cmpgt_epu32_mask(lanes, _mm512_sub_epi32(hA, offset), windowLast) |
                            _mm512_mask_cmpgt_epu32_mask(lanes, _mm512_sub_epi32(hB, offset), windowLast) |
                            _mm512_mask_cmpgt_epu32_mask(lanes, _mm512_sub_epi32(vA, row), one) |
                            _mm512_mask_cmpgt_epu32_mask(lanes, _mm512_sub_epi32(vB, row), one);
  return outside == 0;
}

FCT_AVX512 void integratePacket(const SiddonPacketLayout& layout, const SiddonPacketRay* rays,
                                                         int count, float* values) {
  constexpr int L = SiddonPacketKernel::kLanes;
  constexpr int W = SiddonPacketKernel::kWindow;
  int first = -1;  // the first lane whose ray meets the volume
  for (int r = 0; r < count && first < 0; ++r) {
    if (rays[r].uEnd > rays[r].uBegin) first = r;
  }
  if (first < 0) {
    std::fill(values, values + count, 0.0f);
    return;
  }
  // Lanes without a ray, or whose ray misses the volume, follow the first ray over an empty range: their path length
  // is 0 in every column, so they add nothing and read only voxels the others read.
  alignas(64) float uBegin[L], uEnd[L], h0[L], hPerU[L], uPerH[L], v0[L], vPerU[L], uPerV[L];
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  int firstLane = first, lastLane = first;
  for (int r = 0; r < L; ++r) {
    const bool own = r < count && rays[r].uEnd > rays[r].uBegin;
    const SiddonPacketRay& ray = own ? rays[r] : rays[first];
    uBegin[r] = static_cast<float>(ray.uBegin);
    uEnd[r] = own ? static_cast<float>(ray.uEnd) : uBegin[r];
    h0[r] = static_cast<float>(ray.h0);
    hPerU[r] = static_cast<float>(ray.hPerU);
    uPerH[r] = inverseSlope(ray.hPerU);
    v0[r] = static_cast<float>(ray.v0);
    vPerU[r] = static_cast<float>(ray.vPerU);
    uPerV[r] = inverseSlope(ray.vPerU);
    if (own) {
      lastLane = r;
      lo = std::min(lo, ray.uBegin);
      hi = std::max(hi, ray.uEnd);
    }
  }
  const __m512 begin = _mm512_load_ps(uBegin), end = _mm512_load_ps(uEnd);
  const __m512 hStart = _mm512_load_ps(h0), hSlope = _mm512_load_ps(hPerU), hInverse = _mm512_load_ps(uPerH);
  const __m512 vStart = _mm512_load_ps(v0), vSlope = _mm512_load_ps(vPerU), vInverse = _mm512_load_ps(uPerV);
  const __m512 zero = _mm512_setzero_ps();
  const __m512i hLast = _mm512_set1_epi32(layout.countH - 1), vLast = _mm512_set1_epi32(layout.countV - 1);
  const __m512i windowLast = _mm512_set1_epi32(W - 1);
  const int mFirst = std::clamp(static_cast<int>(std::floor(lo)), 0, layout.countD - 1);
  const int mLast = std::clamp(static_cast<int>(std::floor(hi)), 0, layout.countD - 1);

  __m512 cs = _mm512_min_ps(_mm512_max_ps(_mm512_set1_ps(static_cast<float>(mFirst)), begin), end);
  __m512i hA = cellAt(cs, hSlope, hStart, hLast), vA = cellAt(cs, vSlope, vStart, vLast);
  __m512 acc0 = zero, acc1 = zero;
  __m512d sumLow = _mm512_setzero_pd(), sumHigh = _mm512_setzero_pd();
  for (int m = mFirst; m <= mLast; ++m) {
    // The part [cs, ce] of each ray in column m, its cells at both ends and where it crosses H and V.
    const __m512 ce = _mm512_min_ps(_mm512_max_ps(_mm512_set1_ps(static_cast<float>(m + 1)), begin), end);
    const __m512 len = _mm512_sub_ps(ce, cs);
    const __m512i hB = cellAt(ce, hSlope, hStart, hLast), vB = cellAt(ce, vSlope, vStart, vLast);
    const __mmask16 inColumn = _mm512_cmp_ps_mask(len, zero, _CMP_GT_OQ);
    if (inColumn) {
      // Lanes that cross a boundary of H or V in this column (most columns have no crossing of V, many none of H;
      // where no lane crosses, the terms of that crossing are exactly zero and are skipped).
      const __mmask16 crossH = _mm512_cmpneq_epi32_mask(hA, hB), crossV = _mm512_cmpneq_epi32_mask(vA, vB);
      const float* slab = layout.data + static_cast<std::ptrdiff_t>(m) * layout.strideD;
      // The window: the rays of a packet fan out monotonically along H, so the packet's first and last rays bound
      // the others; checked over the lanes in this column, and found by full reductions where the guess fails.
      const __m512i hLow = _mm512_min_epi32(hA, hB), vLow = _mm512_min_epi32(vA, vB);
      int start = std::min(std::min(laneValue(hLow, firstLane), laneValue(hLow, lastLane)), layout.countH - W);
      int vMin = std::min(laneValue(vLow, firstLane), laneValue(vLow, lastLane));
      if (!fitsWindow(inColumn, hA, hB, vA, vB, start, vMin)) {
        start = std::min(_mm512_mask_reduce_min_epi32(inColumn, hLow), layout.countH - W);
        vMin = _mm512_mask_reduce_min_epi32(inColumn, vLow);
      }
      __m512 v00, v10, v01, v11;  // values at (hA, vA), (hB, vA), (hA, vB), (hB, vB)
      if (fitsWindow(inColumn, hA, hB, vA, vB, start, vMin)) {
        // Two rows of W voxels hold every lane's values: permute them out.
        const float* row0 = slab + static_cast<std::ptrdiff_t>(vMin) * layout.strideV + start;
        const float* row1 = vMin + 1 < layout.countV ? row0 + layout.strideV : row0;
        const __m512 low0 = _mm512_loadu_ps(row0), high0 = _mm512_loadu_ps(row0 + 16);
        const __m512 low1 = _mm512_loadu_ps(row1), high1 = _mm512_loadu_ps(row1 + 16);
        // The rows of a few columns ahead (about where the packet will be): hides the cache misses of the walk.
        // Addresses as integers: near the volume's end they may lie past it, where a prefetch is harmless.
        const std::uintptr_t ahead = static_cast<std::uintptr_t>(kPrefetchColumns * layout.strideD) * sizeof(float);
        for (const float* row : {row0, row1}) {
          const std::uintptr_t address = reinterpret_cast<std::uintptr_t>(row) + ahead;
          _mm_prefetch(reinterpret_cast<const char*>(address), _MM_HINT_T0);
          _mm_prefetch(reinterpret_cast<const char*>(address + (W - 1) * sizeof(float)), _MM_HINT_T0);
        }
        const __m512i offset = _mm512_set1_epi32(start);
        // Lanes outside this column may lie outside the window: clamp their (unused) positions into it.
        const __m512i iA = _mm512_min_epu32(_mm512_sub_epi32(hA, offset), windowLast);
        const __m512i iB = _mm512_min_epu32(_mm512_sub_epi32(hB, offset), windowLast);
        const __m512i rowMin = _mm512_set1_epi32(vMin);
        const __mmask16 upperA = _mm512_cmpgt_epi32_mask(vA, rowMin), upperB = _mm512_cmpgt_epi32_mask(vB, rowMin);
        v00 = pick(low0, high0, low1, high1, iA, upperA);
        v10 = crossH ? pick(low0, high0, low1, high1, iB, upperA) : v00;
        v01 = crossV ? pick(low0, high0, low1, high1, iA, upperB) : v00;
        v11 = !crossV ? v10 : crossH ? pick(low0, high0, low1, high1, iB, upperB) : v01;
      } else {
        // The lanes spread over more than the window (rare): load each lane's voxels one by one.
        alignas(64) std::int32_t ha[L], hb[L], va[L], vb[L];
        alignas(64) float f00[L], f10[L], f01[L], f11[L];
        _mm512_store_si512(ha, hA);
        _mm512_store_si512(hb, hB);
        _mm512_store_si512(va, vA);
        _mm512_store_si512(vb, vB);
        for (int r = 0; r < L; ++r) {
          const float* rowA = slab + static_cast<std::ptrdiff_t>(va[r]) * layout.strideV;
          const float* rowB = slab + static_cast<std::ptrdiff_t>(vb[r]) * layout.strideV;
          f00[r] = rowA[ha[r]];
          f10[r] = rowA[hb[r]];
          f01[r] = rowB[ha[r]];
          f11[r] = rowB[hb[r]];
        }
        v00 = _mm512_load_ps(f00);
        v10 = _mm512_load_ps(f10);
        v01 = _mm512_load_ps(f01);
        v11 = _mm512_load_ps(f11);
      }
      // The column's integral: len·v00, plus the part after the H crossing at v10 - v00, after the V crossing at
      // v01 - v00, and after both at the corner term (exact for either crossing order). A skipped term would have
      // added an exact zero, so a lane's sum does not depend on whether other lanes cross.
      acc0 = _mm512_fmadd_ps(len, v00, acc0);
      __m512 afterH = zero;
      if (crossH) {
        const __m512 uH = _mm512_mul_ps(_mm512_sub_ps(_mm512_cvtepi32_ps(_mm512_max_epi32(hA, hB)), hStart), hInverse);
        afterH = _mm512_min_ps(_mm512_max_ps(_mm512_sub_ps(ce, uH), zero), len);
        acc1 = _mm512_fmadd_ps(afterH, _mm512_sub_ps(v10, v00), acc1);
      }
      if (crossV) {
        const __m512 uV = _mm512_mul_ps(_mm512_sub_ps(_mm512_cvtepi32_ps(_mm512_max_epi32(vA, vB)), vStart), vInverse);
        const __m512 afterV = _mm512_min_ps(_mm512_max_ps(_mm512_sub_ps(ce, uV), zero), len);
        const __m512 dV = _mm512_sub_ps(v01, v00);
        acc0 = _mm512_fmadd_ps(afterV, dV, acc0);
        if (crossH) {
          acc1 = _mm512_fmadd_ps(_mm512_min_ps(afterH, afterV), _mm512_sub_ps(_mm512_sub_ps(v11, v10), dV), acc1);
        }
      }
    }
    if ((m + 1) % kFlushColumns == 0 || m == mLast) {
      const __m512 block = _mm512_add_ps(acc0, acc1);
      sumLow = _mm512_add_pd(sumLow, _mm512_cvtps_pd(_mm512_castps512_ps256(block)));
      sumHigh = _mm512_add_pd(sumHigh, _mm512_cvtps_pd(_mm256_castpd_ps(_mm512_extractf64x4_pd(_mm512_castps_pd(block), 1))));
      acc0 = zero;
      acc1 = zero;
    }
    cs = ce;
    hA = hB;
    vA = vB;
  }
  alignas(64) double sums[L];
  _mm512_store_pd(sums, sumLow);
  _mm512_store_pd(sums + 8, sumHigh);
  for (int r = 0; r < count; ++r) {
    values[r] = rays[r].uEnd > rays[r].uBegin ? static_cast<float>(sums[r] * rays[r].mmPerU) : 0.0f;
  }
}

}  // namespace

void SiddonPacketKernel::integrate(const SiddonPacketLayout& layout, const SiddonPacketRay* rays, int count,
                                   float* values) {
  integratePacket(layout, rays, count, values);
}

#else

void SiddonPacketKernel::integrate(const SiddonPacketLayout&, const SiddonPacketRay*, int count, float* values) {
  std::fill(values, values + count, 0.0f);  // unreachable: available() is false on this platform
}

#endif

}  // namespace fct
