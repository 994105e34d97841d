#pragma once
// A synthetic landmark case for the landmark pose tests: three oblique C-arm views (SID 1000-1500 mm, 0.3 mm
// pixels) around an isocentre, CT landmarks on a bone-sized object, and a known pose T_world_from_ct.

#include <map>
#include <string>

#include "Geometry/Camera.h"
#include "Geometry/Landmarks.h"
#include "Geometry/RigidPose.h"

namespace fct::test {

/// Centre of the synthetic bone in the CT frame (LPS mm).
inline Eigen::Vector3d boneCentre_ct_mm() { return Eigen::Vector3d(120.0, 140.0, 90.0); }

/// A C-arm view: rotated by `orbit_deg` about the world z axis and tilted by `tilt_deg`, looking at the origin.
inline Camera cArmView(double orbit_deg, double tilt_deg, double sid_mm) {
  Eigen::Matrix3d base;  // camera x = world x, camera z (towards the detector) = world y, camera y = world -z
  base << 1, 0, 0, 0, 0, 1, 0, -1, 0;
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(orbit_deg * M_PI / 180.0, Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(tilt_deg * M_PI / 180.0, Eigen::Vector3d::UnitX()))
                                .toRotationMatrix() *
                            base;
  return Camera::lookingAt(Eigen::Vector3d::Zero(), R, 0.6 * sid_mm, sid_mm, 1024, 1024, 0.3);
}

/// Views "AP", "OBL" and "LAT" at SID 1000, 1200 and 1500 mm.
inline std::map<std::string, Camera> threeViews() {
  return {{"AP", cArmView(5.0, 12.0, 1000.0)}, {"OBL", cArmView(50.0, -15.0, 1200.0)},
          {"LAT", cArmView(95.0, 8.0, 1500.0)}};
}

/// The true pose: rotated about the bone centre and placed near the isocentre.
inline Eigen::Isometry3d truePose() {
  PoseParameters params;
  params.rotation_deg = Eigen::Vector3d(12.0, -7.0, 25.0);
  params.translation_mm = -boneCentre_ct_mm() + Eigen::Vector3d(8.0, -5.0, 12.0);
  return RigidPose::toTransform(params, boneCentre_ct_mm());
}

/// Eight CT landmarks spread over a 60 mm radius around the bone centre (not coplanar).
inline std::vector<CtLandmark> ctLandmarks() {
  const Eigen::Vector3d c = boneCentre_ct_mm();
  return {{"ASIS_L", c + Eigen::Vector3d(55, 10, 20)},   {"ASIS_R", c + Eigen::Vector3d(-55, 12, 18)},
          {"PSIS_L", c + Eigen::Vector3d(30, -40, 35)},  {"PSIS_R", c + Eigen::Vector3d(-32, -42, 33)},
          {"PUB", c + Eigen::Vector3d(0, 45, -40)},       {"SACRUM", c + Eigen::Vector3d(2, -50, 5)},
          {"ISCH_L", c + Eigen::Vector3d(38, 5, -50)},   {"ISCH_R", c + Eigen::Vector3d(-40, 8, -48)}};
}

/// Landmarks with exact clicks (projections at the true pose) in the given views.
inline Landmarks exactLandmarks(const std::map<std::string, Camera>& cameras,
                                const Eigen::Isometry3d& T_world_from_ct = truePose()) {
  Landmarks landmarks;
  landmarks.ct = ctLandmarks();
  for (const auto& [view, camera] : cameras) {
    for (const auto& lm : landmarks.ct) {
      landmarks.imageByView[view].push_back({lm.name, camera.project(T_world_from_ct * lm.p_ct_mm)});
    }
  }
  return landmarks;
}

/// Rotation angle (deg) and translation distance (mm) between two poses.
inline std::pair<double, double> poseDifference(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  const Eigen::Isometry3d d = a.inverse() * b;
  return {Eigen::AngleAxisd(d.linear()).angle() * 180.0 / M_PI, (a.translation() - b.translation()).norm()};
}

}  // namespace fct::test
