#pragma once
// PoseErrorMetrics: how far an estimated bone pose is from the true one, as the paper and surgeons measure it.
// - sTRE (surface target registration error): mean and maximum over the bone surface points (BoneSurface: the
//   boundary voxels of {HU >= bone threshold} of the CT, at most 20,000 of them) of |T_est p - T_true p|.
// - mTRE: mean of |T_est p - T_true p| over a regular grid of 10 x 10 x 10 points spanning the axis-aligned bounding
//   box (CT frame) of those surface points, i.e. a volume region around the bone, not only its surface.
// - rotation error: the angle of R_est * R_true^T in degrees (0..180).
// - translation error: |T_est c - T_true c| in mm at the bone centre c (the surface points' centroid).
// - single-plane components: each surface point's displacement split along the viewing ray from the X-ray source
//   through the bone centre's true position (out-of-plane: the depth one view hardly sees) and across it (in-plane),
//   each averaged over the points.
// Success is sTRE mean < 2 mm (the paper's definition); the capture range is read off per-bin success rates.

#include <Eigen/Geometry>

#include <vector>

#include "Base/Result.h"
#include "Image/BoneSurface.h"
#include "Image/Volume.h"

namespace fct {

/// The error of one estimated pose against the truth (all in mm, except rotation_deg).
struct PoseError {
  double streMean_mm = 0.0;     ///< mean bone-surface point distance
  double streMax_mm = 0.0;      ///< maximum bone-surface point distance
  double mtre_mm = 0.0;         ///< mean distance over the grid of the bone's bounding box
  double rotation_deg = 0.0;    ///< angle of the residual rotation R_est * R_true^T
  double translation_mm = 0.0;  ///< distance of the bone centre's two images
};

/// The error of one estimated pose as one view sees it (mm): across and along the viewing ray of the bone centre.
struct ViewPlaneError {
  double inPlaneMean_mm = 0.0;     ///< mean length of the displacements' parts across the ray (seen by the view)
  double outOfPlaneMean_mm = 0.0;  ///< mean length of their parts along the ray (depth)
};

/// Success rate of the trials whose initial sTRE falls in one bin [low_mm, high_mm).
struct InitialDistanceBin {
  double low_mm = 0.0;
  double high_mm = 0.0;
  int trials = 0;
  int successes = 0;
};

/// Pose error measures of one CT's bone.
class PoseErrorMetrics {
 public:
  /// The paper's success threshold on the mean sTRE, mm.
  static constexpr double kSuccessThreshold_mm = 2.0;
  /// The success rate a bin needs to count inside the capture range.
  static constexpr double kCaptureSuccessRate = 0.95;
  /// Grid points per axis of the mTRE region.
  static constexpr int kGridPointsPerAxis = 10;

  /// Measures for the bone of `ct` (surface at `boneThreshold_hu`). Fails as BoneSurface::extract does (empty CT, no
  /// voxel at the threshold, with the CT's value range).
  static Result<PoseErrorMetrics> create(const Volume& ct, double boneThreshold_hu = BoneSurface::kDefaultThreshold_hu);
  /// Measures for an already extracted bone surface (never fails).
  static PoseErrorMetrics fromSurface(BoneSurface surface);

  /// The error of T_estimate against T_truth (both T_world_from_ct, LPS mm). Identical poses give all zeros; a pure
  /// translation by d mm gives d for both sTREs, the mTRE and the translation, and 0 deg.
  PoseError measure(const Eigen::Isometry3d& T_estimate, const Eigen::Isometry3d& T_truth) const;
  /// The sTRE points' displacements T_estimate p - T_truth p split along and across the unit ray from
  /// `source_world_mm` (the view's X-ray source, world LPS mm) through the true bone centre T_truth c. A shift along
  /// that ray is all out-of-plane, one perpendicular to it all in-plane. A source at the bone centre gives the whole
  /// sTRE as in-plane.
  ViewPlaneError measureInView(const Eigen::Isometry3d& T_estimate, const Eigen::Isometry3d& T_truth,
                               const Eigen::Vector3d& source_world_mm) const;
  /// True when the error counts as a successful registration (sTRE mean < kSuccessThreshold_mm).
  static bool isSuccess(const PoseError& error) { return error.streMean_mm < kSuccessThreshold_mm; }
  /// Capture range in mm: the upper edge of the last bin of the longest run of bins, from the first one, whose
  /// success rate is >= 95 % (bins without trials end the run). 0 when the first bin already fails. Bins must be in
  /// increasing order.
  static double captureRange_mm(const std::vector<InitialDistanceBin>& bins);

  /// The bone surface (sTRE points, centre).
  const BoneSurface& surface() const { return m_surface; }
  /// The mTRE grid points, CT LPS mm.
  const std::vector<Eigen::Vector3d>& regionPoints_ct_mm() const { return m_regionPoints_ct_mm; }

 private:
  explicit PoseErrorMetrics(BoneSurface surface) : m_surface(std::move(surface)) {}

  BoneSurface m_surface;
  std::vector<Eigen::Vector3d> m_regionPoints_ct_mm;
};

}  // namespace fct
