#pragma once
// Camera: a calibrated C-arm view as a pinhole camera, world (LPS mm) -> detector pixels.
// Camera frame: origin at the X-ray source, +z along the principal ray toward the detector,
// +x along increasing column, +y along increasing row. Pixel (0,0) is the centre of the top-left pixel.
// K = [[f/du, 0, cu], [0, f/dv, cv], [0, 0, 1]] with f the source-to-detector distance in mm.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "Base/Result.h"

namespace fct {

/// A ray in world coordinates: origin (the X-ray source) and unit direction, both LPS mm.
struct Ray {
  Eigen::Vector3d origin_world_mm;
  Eigen::Vector3d direction_world;  ///< unit length
};

/// Detector intrinsics of one view.
struct CameraIntrinsics {
  int cols = 0;                                            ///< detector width in pixels
  int rows = 0;                                            ///< detector height in pixels
  Eigen::Vector2d pixelSpacing_mm{1.0, 1.0};               ///< (du, dv): pixel size along columns, rows
  double sourceToDetector_mm = 1000.0;                     ///< f: source to detector plane along the principal ray
  Eigen::Vector2d principalPoint_px{0.0, 0.0};             ///< (cu, cv): foot of the principal ray on the detector
};

/// A pinhole camera: intrinsics and the camera's pose in the world.
class Camera {
 public:
  Camera() = default;

  /// Validates and builds a camera: positive sizes and spacing, finite numbers, a proper rotation (det +1),
  /// a principal point within one detector size of the detector. Returns an error naming the bad value.
  static Result<Camera> create(const CameraIntrinsics& intrinsics, const Eigen::Isometry3d& T_world_from_camera);

  /// Builds a camera from a 3x4 projection matrix (world mm -> homogeneous pixels) and the detector size and
  /// pixel spacing. Fails on a singular matrix, a skewed K, or f/du and f/dv that disagree by more than 1 %.
  static Result<Camera> fromProjectionMatrix(const Eigen::Matrix<double, 3, 4>& P_px_from_world, int cols, int rows,
                                             const Eigen::Vector2d& pixelSpacing_mm);

  /// A standard C-arm view for simulation: source at sourceToPatient_mm from isocentre_world_mm on the -z side of a
  /// camera rotated by R_world_from_camera, detector at sourceToDetector_mm, principal point at the detector centre.
  static Camera lookingAt(const Eigen::Vector3d& isocentre_world_mm, const Eigen::Matrix3d& R_world_from_camera,
                          double sourceToPatient_mm, double sourceToDetector_mm, int cols, int rows,
                          double pixelSpacing_mm);

  const CameraIntrinsics& intrinsics() const { return m_intrinsics; }
  /// Pose of the camera (source) frame in the world, LPS mm.
  const Eigen::Isometry3d& T_world_from_camera() const { return m_T_world_from_camera; }
  /// Inverse of T_world_from_camera().
  Eigen::Isometry3d T_camera_from_world() const { return m_T_world_from_camera.inverse(); }
  /// Intrinsic matrix K in pixels.
  Eigen::Matrix3d K() const;
  /// Projection matrix P = K [R | t], world mm -> homogeneous pixels.
  Eigen::Matrix<double, 3, 4> P_px_from_world() const;
  /// X-ray source position in world LPS mm.
  Eigen::Vector3d sourcePosition_world_mm() const { return m_T_world_from_camera.translation(); }

  /// Projects a world point to pixel (col,row); returns false in `inFront` if the point is at or behind the source.
  Eigen::Vector2d project(const Eigen::Vector3d& p_world_mm, bool* inFront = nullptr) const;
  /// The ray from the source through pixel (col,row) (continuous pixel coordinates).
  Ray backProject(const Eigen::Vector2d& uv_px) const;
  /// World position in mm of pixel (col,row) on the detector plane.
  Eigen::Vector3d detectorPoint_world_mm(const Eigen::Vector2d& uv_px) const;

  /// The camera of pyramid level `level`: detector downsampled by 2^level per axis (each new pixel covers a
  /// 2^level x 2^level block). Pixel size scales by 2^level and the principal point maps exactly:
  /// c' = (c + 0.5) / 2^level - 0.5. The detector size is floor(size / 2^level).
  Camera downsampled(int level) const;

 private:
  CameraIntrinsics m_intrinsics;
  Eigen::Isometry3d m_T_world_from_camera = Eigen::Isometry3d::Identity();
};

}  // namespace fct
