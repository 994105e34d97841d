#pragma once
// SiddonPacketKernel: the exact voxel-box line integrals of up to 16 neighbouring rays at once with AVX-512
// (SiddonRayCaster uses it when the processor has AVX-512F). The rays share a dominant axis D: every ray crosses
// each slab of D (a "column") once and, since it moves at most one voxel along each other axis per column, meets at
// most four voxels there. Per column, for all lanes at once: the entry and exit point, the crossing of each minor
// axis, the four voxel values and the exact path length in each. The values are not gathered: the lanes lie close
// together along the minor axis H that is contiguous in memory, so two rows of 32 voxels are loaded and each lane's
// values are picked out of them by in-register permutes. Columns where the lanes spread too far fall back to per-lane
// loads with the same arithmetic. Positions are float (a few 1e-5 voxel), sums are flushed to double every 64
// columns: about 1e-6 of a ray's integral.

#include <cstddef>

namespace fct {

/// A volume's voxels as the kernel walks them: slab m of the dominant axis D starts at data + m·strideD; inside a
/// slab, H is contiguous (stride 1) and V has stride strideV. Index frame: voxel (d, h, v) covers [d, d+1) x [h, h+1)
/// x [v, v+1) ("grid" coordinates = voxel index + 0.5).
struct SiddonPacketLayout {
  const float* data = nullptr;
  int countD = 0, countH = 0, countV = 0;  ///< voxels along D, H and V
  std::ptrdiff_t strideD = 0;              ///< floats between slabs of D
  std::ptrdiff_t strideV = 0;              ///< floats between rows of V inside a slab
};

/// One ray in the layout's grid coordinates, parametrized by its D coordinate u over [uBegin, uEnd] (already
/// clipped to the volume): its H coordinate is h0 + hPerU·u and its V coordinate v0 + vPerU·u, with |hPerU| <= 1
/// and |vPerU| <= 1 (D dominant). mmPerU converts the integral over u into the ray's line integral (mm per unit u).
struct SiddonPacketRay {
  double uBegin = 0.0, uEnd = 0.0;  ///< uBegin <= uEnd; equal: the ray misses the volume
  double h0 = 0.0, hPerU = 0.0;
  double v0 = 0.0, vPerU = 0.0;
  double mmPerU = 0.0;
};

/// The AVX-512 packet integrator of SiddonRayCaster.
class SiddonPacketKernel {
 public:
  /// Rays per packet.
  static constexpr int kLanes = 16;
  /// Voxels of H loaded per row; a layout needs countH >= kWindow.
  static constexpr int kWindow = 32;

  /// True when this processor runs the kernel (AVX-512F).
  static bool available();

  /// Writes values[r] = the line integral of ray r (value·mm for raw values) for r < count (1..kLanes). Each value
  /// depends only on its own ray and the layout, not on the other rays of the packet. The layout must have
  /// countH >= kWindow; call only when available().
  static void integrate(const SiddonPacketLayout& layout, const SiddonPacketRay* rays, int count, float* values);
};

}  // namespace fct
