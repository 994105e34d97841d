#pragma once
// TrackPoseChart: the chart of a tracked sequence, the six pose parameters of every frame (rotations rx, ry, rz in
// degrees about the bone centre, translations tx, ty, tz of the centre in mm; RigidPose's convention) as their change
// since frame 0, against the frame index. Drawn by LineChart: `fluoroct track` writes it as track.png, the Studio's
// Track step shows it.

#include <Eigen/Core>

#include <vector>

#include "Evaluation/LineChart.h"
#include "Tracking/CineTracker.h"

namespace fct {

/// Builds the pose chart of tracked frames.
class TrackPoseChart {
 public:
  /// The chart of `frames` (in order, frame 0 first) with parameters about rotationCentre_ct_mm (CT LPS mm), at
  /// width_px x height_px; a frame whose pose is not a rotation gets no point. No frames: no points.
  static ChartSpec spec(const std::vector<TrackedFrame>& frames, const Eigen::Vector3d& rotationCentre_ct_mm,
                        int width_px = 900, int height_px = 560);
};

}  // namespace fct
