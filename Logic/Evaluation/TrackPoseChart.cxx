#include "Evaluation/TrackPoseChart.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>

#include "Geometry/RigidPose.h"

namespace fct {

ChartSpec TrackPoseChart::spec(const std::vector<TrackedFrame>& frames, const Eigen::Vector3d& rotationCentre_ct_mm,
                               int width_px, int height_px) {
  static constexpr std::array<const char*, 6> kNames{"rx (deg)", "ry (deg)", "rz (deg)",
                                                     "tx (mm)",  "ty (mm)",  "tz (mm)"};
  ChartSpec chart;
  chart.title = "Pose change since frame 0 (about the bone centre)";
  chart.xLabel = "frame";
  chart.yLabel = "deg / mm";
  chart.width_px = width_px;
  chart.height_px = height_px;
  for (const char* name : kNames) chart.series.push_back(ChartSeries{name, {}, {}, true});
  std::optional<PoseVector> reference;
  double lo = 0.0, hi = 1.0;
  for (const TrackedFrame& frame : frames) {
    auto params = RigidPose::fromTransform(frame.T_world_from_ct, rotationCentre_ct_mm);
    PoseVector change = PoseVector::Constant(std::numeric_limits<double>::quiet_NaN());
    if (params) {
      if (!reference) reference = params.value().asVector();
      change = params.value().asVector() - *reference;
    }
    for (std::size_t k = 0; k < kNames.size(); ++k) {
      const double value = change[static_cast<int>(k)];
      chart.series[k].x.push_back(frame.index);
      chart.series[k].y.push_back(value);
      if (std::isfinite(value)) lo = std::min(lo, value), hi = std::max(hi, value);
    }
  }
  chart.yMin = std::floor(lo);
  chart.yMaxAtLeast = hi;
  return chart;
}

}  // namespace fct
