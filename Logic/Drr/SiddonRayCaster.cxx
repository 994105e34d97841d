#include "Drr/SiddonRayCaster.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <limits>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "Drr/DrrRayGeometry.h"

namespace fct {

namespace {
/// Rays whose dominant axis has at least this many boundaries per boundary of the other two are traversed in runs
/// (callgrind on the pelvis CT: runs cost more instructions than single steps below about 2 boundaries per run).
constexpr long kMinRunLength = 3;

/// The index axis (0 = i, 1 = j, 2 = k) along which `d` has the largest component; the first on a tie.
int dominantAxis(const Eigen::Vector3d& d) {
  int axis = std::abs(d.y()) > std::abs(d.x()) ? 1 : 0;
  if (std::abs(d.z()) > std::abs(d[axis])) axis = 2;
  return axis;
}

/// Up to SiddonPacketKernel::kLanes consecutive pixels of one detector row whose rays share their dominant axis.
struct RayPacket {
  std::size_t first = 0;  ///< position of the first pixel in the render's pixel list
  int count = 0;
  int axis = 0;
};
}  // namespace

SiddonRayCaster::SiddonRayCaster(std::shared_ptr<const DrrVolume> volume, SiddonTraversal traversal)
    : IndexSpaceRayCaster(std::move(volume)),
      m_packets(traversal == SiddonTraversal::Fastest && SiddonPacketKernel::available()) {}

SiddonPacketLayout SiddonRayCaster::packetLayout(int axis) const {
  const DrrVolume& vol = volume();
  const Eigen::Vector3i& n = vol.dims();
  const std::ptrdiff_t slice = static_cast<std::ptrdiff_t>(n.x()) * n.y();
  if (axis == 1) return {vol.data(), n.y(), n.x(), n.z(), n.x(), slice};
  if (axis == 2) return {vol.data(), n.z(), n.x(), n.y(), slice, n.x()};
  return {vol.valuesJFastest(), n.x(), n.y(), n.z(), n.y(), slice};
}

DrrRenderStats SiddonRayCaster::integratePixels(const Camera& levelCamera, const Eigen::Isometry3d& T_world_from_ct,
                                                const std::int32_t* pixels, std::size_t count, float* values) const {
  if (!m_packets) return IndexSpaceRayCaster::integratePixels(levelCamera, T_world_from_ct, pixels, count, values);
  const DrrVolume& vol = volume();
  const DrrRayGeometry geometry(levelCamera, T_world_from_ct, vol.T_ijk_from_ct());
  const Eigen::Vector3d& source_ijk = geometry.source_ijk();
  const int cols = geometry.cols();
  const auto pixelAt = [&](std::size_t n) { return pixels ? static_cast<std::int64_t>(pixels[n]) : static_cast<std::int64_t>(n); };

  // Packets are formed from the pixel list alone (not from the threads' share of it), and each ray is integrated
  // along its own dominant axis, so a pixel's value does not depend on the list or the thread count.
  std::vector<RayPacket> packets;
  packets.reserve(count / 8 + 1);
  std::int64_t previous = -2;
  bool alongI = false;
  for (std::size_t n = 0; n < count; ++n) {
    const std::int64_t index = pixelAt(n);
    const int row = static_cast<int>(index / cols);
    const int col = static_cast<int>(index - static_cast<std::int64_t>(row) * cols);
    const int axis = dominantAxis(geometry.detectorPoint_ijk(col, row) - source_ijk);
    RayPacket* open = packets.empty() ? nullptr : &packets.back();
    if (open && index == previous + 1 && col > 0 && open->axis == axis && open->count < SiddonPacketKernel::kLanes) {
      ++open->count;
    } else {
      packets.push_back({n, 1, axis});
    }
    alongI = alongI || axis == 0;
    previous = index;
  }
  // The kernel needs a window's worth of voxels along the contiguous axis (i, or j for rays along i).
  const Eigen::Vector3i& n = vol.dims();
  const bool usable[3] = {n.y() >= SiddonPacketKernel::kWindow, n.x() >= SiddonPacketKernel::kWindow,
                          n.x() >= SiddonPacketKernel::kWindow};
  SiddonPacketLayout layouts[3];
  for (int axis = 0; axis < 3; ++axis) {
    if (usable[axis] && (axis != 0 || alongI)) layouts[axis] = packetLayout(axis);  // before the threads start
  }
  const Eigen::Vector3d grid0 = source_ijk.array() + 0.5;  // grid coordinates: voxel m covers [m, m+1)
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, packets.size(), 8), [&](const tbb::blocked_range<std::size_t>& range) {
    SiddonPacketRay rays[SiddonPacketKernel::kLanes];
    for (std::size_t p = range.begin(); p != range.end(); ++p) {
      const RayPacket& packet = packets[p];
      const int d = packet.axis, h = d == 0 ? 1 : 0, v = d == 2 ? 1 : 2;
      for (int r = 0; r < packet.count; ++r) {
        const std::int64_t index = pixelAt(packet.first + static_cast<std::size_t>(r));
        const int row = static_cast<int>(index / cols);
        const int col = static_cast<int>(index - static_cast<std::int64_t>(row) * cols);
        const Eigen::Vector3d pixel_ijk = geometry.detectorPoint_ijk(col, row);
        if (!usable[d]) {
          values[packet.first + static_cast<std::size_t>(r)] =
              static_cast<float>(integrateIjk(source_ijk, pixel_ijk, geometry.rayLength_mm(col, row)));
          continue;
        }
        const Eigen::Vector3d dir = pixel_ijk - source_ijk;
        SiddonPacketRay& ray = rays[r];
        ray = SiddonPacketRay{};
        double t0 = 0.0, t1 = 1.0;
        if (vol.hasContent() &&
            DrrRayGeometry::clipToBox(source_ijk, dir, vol.contentBoxMin_ijk(), vol.contentBoxMax_ijk(), t0, t1)) {
          const double u0 = grid0[d] + t0 * dir[d], u1 = grid0[d] + t1 * dir[d];
          ray.uBegin = std::min(u0, u1);
          ray.uEnd = std::max(u0, u1);
          ray.hPerU = dir[h] / dir[d];
          ray.h0 = grid0[h] - ray.hPerU * grid0[d];
          ray.vPerU = dir[v] / dir[d];
          ray.v0 = grid0[v] - ray.vPerU * grid0[d];
          ray.mmPerU = geometry.rayLength_mm(col, row) / std::abs(dir[d]);
        }
      }
      if (usable[d]) SiddonPacketKernel::integrate(layouts[d], rays, packet.count, values + packet.first);
    }
  });
  return {};
}

double SiddonRayCaster::integrateIjk(const Eigen::Vector3d& a_ijk, const Eigen::Vector3d& b_ijk,
                                            double length_mm) const {
  const DrrVolume& vol = volume();
  const Eigen::Vector3d d = b_ijk - a_ijk;
  double t0 = 0.0;
  double t1 = 1.0;
  // Only the box of non-zero voxels contributes; clipping to it skips the air around the patient.
  if (!vol.hasContent() ||
      !DrrRayGeometry::clipToBox(a_ijk, d, vol.contentBoxMin_ijk(), vol.contentBoxMax_ijk(), t0, t1)) {
    return 0.0;
  }

  // Grid coordinates: voxel m covers [m, m+1) along each axis, the volume covers [0, n).
  // Per axis: current voxel index, its step (+1, -1, 0), the matching offset step in the voxel array, the parameter
  // t of the next voxel boundary and the t between boundaries, and the number of boundaries the clipped ray crosses
  // (entry voxel to exit voxel, both inside the grid). Kept in scalars so the loops run in registers.
  const Eigen::Vector3i& n = vol.dims();
  const std::ptrdiff_t stride[3] = {1, n.x(), static_cast<std::ptrdiff_t>(n.x()) * n.y()};
  struct Axis {
    int index, step, size;
    std::ptrdiff_t offsetStep;
    long crossings;
    double tNext, tDelta;
  };
  constexpr double kNever = std::numeric_limits<double>::infinity();
  Axis axes[3];
  std::ptrdiff_t offset = 0;
  for (int a = 0; a < 3; ++a) {
    Axis& axis = axes[a];
    const double g = a_ijk[a] + 0.5;
    axis.size = n[a];
    // Points on the clipped ray have g > -1, where truncation then clamping equals floor then clamping (and is
    // cheaper: floor is a library call without SSE4.1).
    axis.index = std::clamp(static_cast<int>(g + t0 * d[a]), 0, n[a] - 1);
    const int last = std::clamp(static_cast<int>(g + t1 * d[a]), 0, n[a] - 1);
    axis.crossings = std::abs(last - axis.index);  // floor and clamp are monotone: last lies on the side of the step
    offset += axis.index * stride[a];
    if (d[a] > 0.0) {
      axis.step = 1;
      axis.tDelta = 1.0 / d[a];
      axis.tNext = (axis.index + 1 - g) * axis.tDelta;
    } else if (d[a] < 0.0) {
      axis.step = -1;
      axis.tDelta = -1.0 / d[a];
      axis.tNext = (g - axis.index) * axis.tDelta;
    } else {
      axis.step = 0;
      axis.tDelta = kNever;
      axis.tNext = kNever;
    }
    axis.offsetStep = axis.step * stride[a];
  }

  const float* data = vol.data();
  double sum = 0.0;
  double t = t0;
  // The dominant axis (most boundaries per unit t). When it has several boundaries per boundary of the other two
  // (rays near an axis: AP and lateral views), it is crossed in runs; otherwise (oblique rays) every boundary is
  // crossed one at a time.
  const int dominant = static_cast<int>(std::min_element(axes, axes + 3, [](const Axis& p, const Axis& q) {
                                          return p.tDelta < q.tDelta;
                                        }) - axes);
  Axis major = axes[dominant];
  Axis minorA = axes[(dominant + 1) % 3];
  Axis minorB = axes[(dominant + 2) % 3];
  if (major.crossings < kMinRunLength * (minorA.crossings + minorB.crossings + 1)) {
    Axis x = axes[0], y = axes[1], z = axes[2];
    // Crosses the next boundary of `axis`: adds the path in the current voxel and moves to the neighbour. Returns
    // false when the ray ends first (t1) or leaves the grid.
    const auto cross = [&](Axis& axis) {
      if (axis.tNext >= t1) return false;
      sum += (axis.tNext - t) * data[offset];
      t = axis.tNext;
      axis.index += axis.step;
      if (static_cast<unsigned>(axis.index) >= static_cast<unsigned>(axis.size)) {
        t = t1;  // left the grid within rounding of t1: nothing remains
        return false;
      }
      offset += axis.offsetStep;
      axis.tNext += axis.tDelta;
      return true;
    };
    for (;;) {
      if (x.tNext < y.tNext) {
        if (!(x.tNext < z.tNext ? cross(x) : cross(z))) break;
      } else if (!(y.tNext < z.tNext ? cross(y) : cross(z))) {
        break;
      }
    }
  } else {
    // Between two crossings of the minor axes the ray walks a straight line of voxels along the dominant axis, each
    // but the first traversed over exactly tDelta, so a run costs one strided sum of voxel values. Boundaries are
    // counted (an axis whose boundaries are used up gets tNext = infinity), so the walk never leaves the grid.
    for (Axis* axis : {&major, &minorA, &minorB}) {
      if (axis->crossings == 0) axis->tNext = kNever;
    }
    const auto crossMinor = [&](Axis& axis) {
      sum += (axis.tNext - t) * data[offset];
      t = axis.tNext;
      offset += axis.offsetStep;
      axis.tNext = --axis.crossings > 0 ? t + axis.tDelta : kNever;
    };
    const double runsPerT = 1.0 / major.tDelta;
    for (;;) {
      const double tMinor = std::min(minorA.tNext, minorB.tNext);
      // Dominant boundaries strictly before the next minor one (all that remain when the minor axes are used up).
      if (major.tNext < tMinor) {
        const double before = (tMinor - major.tNext) * runsPerT;
        const long run =
            before >= static_cast<double>(major.crossings) ? major.crossings : static_cast<long>(before) + 1;
        sum += (major.tNext - t) * data[offset];
        offset += major.offsetStep;
        double inner0 = 0.0, inner1 = 0.0;  // two accumulators: the adds do not wait on each other
        long m = 1;
        for (; m + 1 < run; m += 2) {
          inner0 += data[offset];
          inner1 += data[offset + major.offsetStep];
          offset += 2 * major.offsetStep;
        }
        if (m < run) {
          inner0 += data[offset];
          offset += major.offsetStep;
        }
        sum += (inner0 + inner1) * major.tDelta;
        t = major.tNext + static_cast<double>(run - 1) * major.tDelta;
        major.crossings -= run;
        major.tNext = major.crossings > 0 ? t + major.tDelta : kNever;
        if (major.tNext < tMinor) continue;  // rounding left a dominant boundary first
      }
      if (tMinor == kNever) break;  // every boundary crossed
      // Explicit branches (not a reference chosen by ?:) keep the axes in registers.
      if (minorA.tNext <= minorB.tNext) {
        crossMinor(minorA);
      } else {
        crossMinor(minorB);
      }
    }
  }
  if (t < t1) sum += (t1 - t) * data[offset];
  return sum * length_mm;
}

}  // namespace fct
