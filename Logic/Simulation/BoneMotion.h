#pragma once
// BoneMotion: a seeded, smooth rigid motion of the bone over a sequence of frames, as during a reduction under live
// fluoroscopy. Each of the six pose parameters (rotations about the world axes through the bone centre, degrees;
// translations of the centre, mm; RigidPose's convention) is a sum of a few sinusoids of random period, amplitude
// and phase, optionally plus a fast jerk: a step of a fixed size in a random direction, ramped in over 1-2 frames
// from a given frame on. Every parameter stays within +-maxTranslation_mm / +-maxRotation_deg of the base pose (the
// sinusoids share what the jerk leaves of the bound). Frame k's pose is the base pose moved by the frame's
// parameters about the bone centre: T_k = M_k * T_base, M_k(p) = R_k (p - c_world) + c_world + t_k.

#include <Eigen/Geometry>

#include <cstdint>
#include <vector>

#include "Base/Result.h"
#include "Geometry/RigidPose.h"

namespace fct {

/// Settings of a bone motion.
struct BoneMotionOptions {
  int frames = 30;                   ///< frames in the sequence, >= 1
  double maxTranslation_mm = 15.0;   ///< bound of each translation parameter, mm, >= 0
  double maxRotation_deg = 10.0;     ///< bound of each rotation parameter, deg, 0..45
  int sinusoids = 3;                 ///< sinusoids per parameter, 1..8
  double minPeriod_frames = 40.0;    ///< shortest period of a sinusoid, frames (sets the speed), >= 2
  double maxPeriod_frames = 120.0;   ///< longest period, frames, >= minPeriod_frames
  int jerkFrame = -1;                ///< first frame of the jerk; < 0: no jerk
  int jerkFrames = 1;                ///< frames over which the jerk ramps in, 1..2
  double jerkTranslation_mm = 3.0;   ///< size of the jerk's translation step (length of the vector), mm
  double jerkRotation_deg = 2.0;     ///< size of the jerk's rotation step (length of the angle vector), deg
  std::uint32_t seed = 1;            ///< drives the periods, amplitudes, phases and jerk direction
};

/// A smooth rigid motion of the bone, frame by frame.
class BoneMotion {
 public:
  /// The motion for `options`. Fails on a frame count below 1, negative or non-finite bounds, a rotation bound above
  /// 45 deg, sinusoids outside 1..8, periods below 2 frames or in the wrong order, a jerk ramp outside 1..2 frames,
  /// or a jerk larger than a bound (naming the setting).
  static Result<BoneMotion> create(const BoneMotionOptions& options);

  /// Number of frames.
  int frameCount() const { return m_options.frames; }
  /// The options the motion was made with.
  const BoneMotionOptions& options() const { return m_options; }
  /// Motion parameters of frame k (0 <= k < frameCount(); clamped): rotations deg, translations mm, about the centre.
  PoseParameters parameters(int frame) const;
  /// The jerk's part of parameters(frame) (zero before the jerk frame and without a jerk).
  PoseParameters jerkParameters(int frame) const;
  /// Frame k's bone pose T_world_from_ct: T_base moved by parameters(k) about the bone centre centre_ct_mm (CT LPS mm).
  Eigen::Isometry3d pose(int frame, const Eigen::Isometry3d& T_base_world_from_ct,
                         const Eigen::Vector3d& centre_ct_mm) const;
  /// pose() of every frame.
  std::vector<Eigen::Isometry3d> poses(const Eigen::Isometry3d& T_base_world_from_ct,
                                       const Eigen::Vector3d& centre_ct_mm) const;

 private:
  /// One sinusoid of one parameter: amplitude * sin(2 pi k / period + phase).
  struct Sinusoid {
    double amplitude = 0.0;
    double period_frames = 1.0;
    double phase_rad = 0.0;
  };

  explicit BoneMotion(const BoneMotionOptions& options) : m_options(options) {}

  BoneMotionOptions m_options;
  std::vector<std::vector<Sinusoid>> m_sinusoids;  ///< per parameter (rx, ry, rz, tx, ty, tz)
  PoseVector m_jerk = PoseVector::Zero();           ///< the full jerk step per parameter
};

}  // namespace fct
