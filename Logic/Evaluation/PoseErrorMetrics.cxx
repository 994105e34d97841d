#include "Evaluation/PoseErrorMetrics.h"

#include <cmath>

namespace fct {

Result<PoseErrorMetrics> PoseErrorMetrics::create(const Volume& ct, double boneThreshold_hu) {
  auto surface = BoneSurface::extract(ct, boneThreshold_hu);
  if (!surface) return fail(surface.error());
  return fromSurface(std::move(surface).value());
}

PoseErrorMetrics PoseErrorMetrics::fromSurface(BoneSurface surface) {
  PoseErrorMetrics metrics(std::move(surface));
  Eigen::Vector3d lo = metrics.m_surface.points_ct_mm().front(), hi = lo;
  for (const Eigen::Vector3d& p : metrics.m_surface.points_ct_mm()) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const int n = kGridPointsPerAxis;
  metrics.m_regionPoints_ct_mm.reserve(static_cast<std::size_t>(n) * n * n);
  for (int k = 0; k < n; ++k) {
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const Eigen::Vector3d t = Eigen::Vector3d(i, j, k) / static_cast<double>(n - 1);
        metrics.m_regionPoints_ct_mm.push_back(lo + (hi - lo).cwiseProduct(t));
      }
    }
  }
  return metrics;
}

PoseError PoseErrorMetrics::measure(const Eigen::Isometry3d& T_estimate, const Eigen::Isometry3d& T_truth) const {
  PoseError error;
  error.streMean_mm = m_surface.meanDistance_mm(T_estimate, T_truth);
  error.streMax_mm = m_surface.maxDistance_mm(T_estimate, T_truth);
  double sum = 0.0;
  for (const Eigen::Vector3d& p : m_regionPoints_ct_mm) sum += (T_estimate * p - T_truth * p).norm();
  error.mtre_mm = sum / static_cast<double>(m_regionPoints_ct_mm.size());
  const Eigen::Matrix3d residual = T_estimate.linear() * T_truth.linear().transpose();
  error.rotation_deg = Eigen::AngleAxisd(residual).angle() * 180.0 / EIGEN_PI;
  const Eigen::Vector3d centre_ct_mm = m_surface.centroid_ct_mm();
  error.translation_mm = (T_estimate * centre_ct_mm - T_truth * centre_ct_mm).norm();
  return error;
}

ViewPlaneError PoseErrorMetrics::measureInView(const Eigen::Isometry3d& T_estimate, const Eigen::Isometry3d& T_truth,
                                              const Eigen::Vector3d& source_world_mm) const {
  const Eigen::Vector3d ray = T_truth * m_surface.centroid_ct_mm() - source_world_mm;
  const double rayLength_mm = ray.norm();
  const Eigen::Vector3d u = rayLength_mm > 0.0 ? Eigen::Vector3d(ray / rayLength_mm) : Eigen::Vector3d::Zero();
  ViewPlaneError error;
  for (const Eigen::Vector3d& p : m_surface.points_ct_mm()) {
    const Eigen::Vector3d d = T_estimate * p - T_truth * p;
    const double along_mm = d.dot(u);
    error.outOfPlaneMean_mm += std::abs(along_mm);
    error.inPlaneMean_mm += (d - along_mm * u).norm();
  }
  const double count = static_cast<double>(m_surface.points_ct_mm().size());
  error.inPlaneMean_mm /= count;
  error.outOfPlaneMean_mm /= count;
  return error;
}

double PoseErrorMetrics::captureRange_mm(const std::vector<InitialDistanceBin>& bins) {
  double range_mm = 0.0;
  for (const InitialDistanceBin& bin : bins) {
    if (bin.trials <= 0 || bin.successes < kCaptureSuccessRate * bin.trials) break;
    range_mm = bin.high_mm;
  }
  return range_mm;
}

}  // namespace fct
