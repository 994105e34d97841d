// TrackPoseChart: the six series are each frame's pose parameters minus frame 0's; a frame whose pose is not a
// rotation gets no point; the chart draws.
#include <gtest/gtest.h>

#include <cmath>

#include "Evaluation/TrackPoseChart.h"
#include "Geometry/RigidPose.h"

TEST(TrackPoseChart, SeriesAreTheChangeSinceFrameZero) {
  const Eigen::Vector3d centre_ct_mm(10.0, -5.0, 30.0);
  fct::PoseParameters base;
  base.rotation_deg = Eigen::Vector3d(2.0, -1.0, 4.0);
  base.translation_mm = Eigen::Vector3d(-10.0, 5.0, -30.0);
  std::vector<fct::TrackedFrame> frames(3);
  for (int f = 0; f < 3; ++f) {
    fct::PoseParameters p = base;
    p.rotation_deg.z() += 1.5 * f;
    p.translation_mm.x() += 2.0 * f;
    frames[static_cast<std::size_t>(f)].index = f;
    frames[static_cast<std::size_t>(f)].T_world_from_ct = fct::RigidPose::toTransform(p, centre_ct_mm);
  }
  frames[2].T_world_from_ct.matrix()(0, 0) = 3.0;  // not a rotation
  const fct::ChartSpec chart = fct::TrackPoseChart::spec(frames, centre_ct_mm);
  ASSERT_EQ(chart.series.size(), 6u);
  EXPECT_EQ(chart.series[2].name, "rz (deg)");
  EXPECT_EQ(chart.series[3].name, "tx (mm)");
  for (const fct::ChartSeries& series : chart.series) {
    ASSERT_EQ(series.x.size(), 3u);
    EXPECT_EQ(series.x[1], 1.0);
    EXPECT_NEAR(series.y[0], 0.0, 1e-9) << series.name;
    EXPECT_TRUE(std::isnan(series.y[2])) << series.name << ": no point for a pose that is not a rotation";
  }
  EXPECT_NEAR(chart.series[2].y[1], 1.5, 1e-9);
  EXPECT_NEAR(chart.series[3].y[1], 2.0, 1e-9);
  EXPECT_NEAR(chart.series[0].y[1], 0.0, 1e-9);
  EXPECT_TRUE(fct::LineChart::draw(chart).ok());
}
