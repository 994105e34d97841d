#include "Simulation/BoneMotion.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "Base/SeededRandom.h"

namespace fct {

namespace {

constexpr int kParameters = 6;
constexpr double kMaxRotationBound_deg = 45.0;
constexpr int kMaxSinusoids = 8;

/// Checks the settings; the message names the one that is wrong.
Status validate(const BoneMotionOptions& o) {
  if (o.frames < 1) return fail(fmt::format("bone motion needs at least 1 frame, got {}", o.frames));
  if (!(o.maxTranslation_mm >= 0.0) || !std::isfinite(o.maxTranslation_mm)) {
    return fail(fmt::format("translation bound must be finite and >= 0 mm, got {}", o.maxTranslation_mm));
  }
  if (!(o.maxRotation_deg >= 0.0 && o.maxRotation_deg <= kMaxRotationBound_deg)) {
    return fail(fmt::format("rotation bound must be 0..{} deg, got {}", kMaxRotationBound_deg, o.maxRotation_deg));
  }
  if (o.sinusoids < 1 || o.sinusoids > kMaxSinusoids) {
    return fail(fmt::format("sinusoids per parameter must be 1..{}, got {}", kMaxSinusoids, o.sinusoids));
  }
  if (!(o.minPeriod_frames >= 2.0) || !(o.maxPeriod_frames >= o.minPeriod_frames) ||
      !std::isfinite(o.maxPeriod_frames)) {
    return fail(fmt::format("sinusoid periods must satisfy 2 <= min <= max frames, got {}..{}", o.minPeriod_frames,
                            o.maxPeriod_frames));
  }
  if (o.jerkFrame >= 0) {
    if (o.jerkFrames < 1 || o.jerkFrames > 2) {
      return fail(fmt::format("the jerk ramps in over 1 or 2 frames, got {}", o.jerkFrames));
    }
    if (!(o.jerkTranslation_mm >= 0.0 && o.jerkTranslation_mm <= o.maxTranslation_mm)) {
      return fail(fmt::format("jerk translation {} mm must be within 0..the translation bound {} mm",
                              o.jerkTranslation_mm, o.maxTranslation_mm));
    }
    if (!(o.jerkRotation_deg >= 0.0 && o.jerkRotation_deg <= o.maxRotation_deg)) {
      return fail(fmt::format("jerk rotation {} deg must be within 0..the rotation bound {} deg", o.jerkRotation_deg,
                              o.maxRotation_deg));
    }
  }
  return Ok{};
}

/// A uniformly random unit vector (the direction of a 3-D standard normal vector).
Eigen::Vector3d randomDirection(SeededRandom& random) {
  Eigen::Vector3d v(random.normal(), random.normal(), random.normal());
  return v.norm() < 1e-12 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d(v.normalized());
}

}  // namespace

Result<BoneMotion> BoneMotion::create(const BoneMotionOptions& options) {
  if (Status valid = validate(options); !valid) return fail(valid.error());
  BoneMotion motion(options);
  SeededRandom random(options.seed ^ 0x9E3779B9u);
  if (options.jerkFrame >= 0) {
    motion.m_jerk.head<3>() = options.jerkRotation_deg * randomDirection(random);
    motion.m_jerk.tail<3>() = options.jerkTranslation_mm * randomDirection(random);
  }
  motion.m_sinusoids.resize(kParameters);
  for (int p = 0; p < kParameters; ++p) {
    const double bound = p < 3 ? options.maxRotation_deg : options.maxTranslation_mm;
    // The sinusoids' amplitudes add up to 70-100 % of what the jerk leaves of the bound, so |sum| stays inside it.
    const double budget = std::max(0.0, bound - std::abs(motion.m_jerk[p])) * random.uniform(0.7, 1.0);
    std::vector<Sinusoid>& terms = motion.m_sinusoids[p];
    double weightSum = 0.0;
    for (int h = 0; h < options.sinusoids; ++h) {
      Sinusoid s;
      s.amplitude = random.uniform(0.2, 1.0);
      s.period_frames = random.uniform(options.minPeriod_frames, options.maxPeriod_frames);
      s.phase_rad = random.uniform(0.0, 2.0 * M_PI);
      weightSum += s.amplitude;
      terms.push_back(s);
    }
    for (Sinusoid& s : terms) s.amplitude *= budget / weightSum;
  }
  return motion;
}

PoseParameters BoneMotion::jerkParameters(int frame) const {
  if (m_options.jerkFrame < 0) return PoseParameters{};
  const double ramp = std::clamp((frame - m_options.jerkFrame + 1) / static_cast<double>(m_options.jerkFrames), 0.0, 1.0);
  return PoseParameters::fromVector(ramp * m_jerk);
}

PoseParameters BoneMotion::parameters(int frame) const {
  const int k = std::clamp(frame, 0, m_options.frames - 1);
  PoseVector v = jerkParameters(k).asVector();
  for (int p = 0; p < kParameters; ++p) {
    for (const Sinusoid& s : m_sinusoids[p]) v[p] += s.amplitude * std::sin(2.0 * M_PI * k / s.period_frames + s.phase_rad);
  }
  return PoseParameters::fromVector(v);
}

Eigen::Isometry3d BoneMotion::pose(int frame, const Eigen::Isometry3d& T_base_world_from_ct,
                                   const Eigen::Vector3d& centre_ct_mm) const {
  // RigidPose's parameters about the centre, applied in the world frame: M = T(params about c_world).
  const Eigen::Vector3d centre_world_mm = T_base_world_from_ct * centre_ct_mm;
  const Eigen::Isometry3d M_world = RigidPose::toTransform(parameters(frame), centre_world_mm);
  return M_world * T_base_world_from_ct;
}

std::vector<Eigen::Isometry3d> BoneMotion::poses(const Eigen::Isometry3d& T_base_world_from_ct,
                                                 const Eigen::Vector3d& centre_ct_mm) const {
  std::vector<Eigen::Isometry3d> out;
  out.reserve(static_cast<std::size_t>(m_options.frames));
  for (int k = 0; k < m_options.frames; ++k) out.push_back(pose(k, T_base_world_from_ct, centre_ct_mm));
  return out;
}

}  // namespace fct
