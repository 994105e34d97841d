#include "InitialPose/LandmarkPoseEstimator.h"

#include <fmt/core.h>
#include <fmt/format.h>

#include <Eigen/Cholesky>
#include <Eigen/SVD>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include <cmath>
#include <limits>
#include <optional>
#include <set>

#include "InitialPose/LandmarkTriangulator.h"

namespace fct {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// The landmarks usable for a pose: CT points with their clicks, in the order of Landmarks::ct.
struct Correspondences {
  std::vector<std::string> names;
  std::vector<Eigen::Vector3d> p_ct_mm;
  std::vector<std::vector<LandmarkClick>> clicks;  ///< per landmark
  std::vector<std::optional<Eigen::Vector3d>> triangulated_world_mm;  ///< per landmark, when clicked in >= 2 views
  std::vector<std::string> triangulationError;  ///< per landmark: why it has no triangulated point (empty if it has)
};

std::string joined(const std::vector<std::string>& names) { return fmt::format("{}", fmt::join(names, ", ")); }

Status checkNotCollinear(const std::vector<Eigen::Vector3d>& points) {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const auto& p : points) centroid += p;
  centroid /= static_cast<double>(points.size());
  Eigen::MatrixXd centred(points.size(), 3);
  for (size_t i = 0; i < points.size(); ++i) centred.row(i) = (points[i] - centroid).transpose();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(centred, Eigen::ComputeThinV);
  const Eigen::Vector3d direction = svd.matrixV().col(0);
  double extent = 0.0, farthest = 0.0;
  for (const auto& p : points) {
    const Eigen::Vector3d d = p - centroid;
    extent = std::max(extent, std::abs(d.dot(direction)));
    farthest = std::max(farthest, (d - d.dot(direction) * direction).norm());
  }
  if (farthest < 0.01 * extent || extent < 1e-6) {
    return fail(fmt::format("the {} CT landmarks are (nearly) collinear: the farthest lies {:.3g} mm from their common "
                            "line over a {:.3g} mm extent; a pose needs landmarks spread in two directions",
                            points.size(), farthest, 2.0 * extent));
  }
  return Ok{};
}

Result<Correspondences> pairLandmarks(const Landmarks& landmarks, const std::map<std::string, Camera>& cameras) {
  std::vector<std::string> known;
  for (const auto& [view, camera] : cameras) known.push_back(view);
  for (const auto& [view, clicks] : landmarks.imageByView) {
    if (!cameras.count(view)) {
      return fail(fmt::format("landmarks are clicked in view '{}' but there is no such view (views: {})", view,
                              known.empty() ? std::string("none") : joined(known)));
    }
  }
  std::map<std::string, size_t> ctIndex;
  for (const auto& landmark : landmarks.ct) {
    if (!landmark.p_ct_mm.allFinite()) {
      return fail(fmt::format("CT landmark '{}' has a NaN or infinite coordinate", landmark.name));
    }
    if (!ctIndex.emplace(landmark.name, ctIndex.size()).second) {
      return fail(fmt::format("CT landmark '{}' is defined twice; landmark names must be unique", landmark.name));
    }
  }
  std::vector<std::vector<LandmarkClick>> clicksByCt(landmarks.ct.size());
  for (const auto& [view, clicks] : landmarks.imageByView) {
    std::set<std::string> seen;
    for (const auto& click : clicks) {
      if (!seen.insert(click.name).second) {
        return fail(fmt::format("landmark '{}' is clicked twice in view '{}'", click.name, view));
      }
      if (!click.uv_px.allFinite()) {
        return fail(fmt::format("landmark '{}' has a NaN or infinite click in view '{}'", click.name, view));
      }
      const auto it = ctIndex.find(click.name);
      if (it == ctIndex.end()) {
        return fail(fmt::format("landmark '{}' is clicked in view '{}' but has no CT point; add it in the CT or remove "
                                "the click",
                                click.name, view));
      }
      clicksByCt[it->second].push_back(LandmarkClick{view, cameras.at(view), click.uv_px});
    }
  }
  Correspondences c;
  for (size_t i = 0; i < landmarks.ct.size(); ++i) {
    if (clicksByCt[i].empty()) {
      return fail(fmt::format("landmark '{}' has a CT point but is clicked in no view; click it or remove it",
                              landmarks.ct[i].name));
    }
    c.names.push_back(landmarks.ct[i].name);
    c.p_ct_mm.push_back(landmarks.ct[i].p_ct_mm);
    c.clicks.push_back(std::move(clicksByCt[i]));
  }
  if (c.names.size() < 4) {
    return fail(fmt::format("only {} landmark{} paired between the CT and the views ({}); at least 4 are needed",
                            c.names.size(), c.names.size() == 1 ? " is" : "s are",
                            c.names.empty() ? std::string("none") : joined(c.names)));
  }
  if (auto status = checkNotCollinear(c.p_ct_mm); !status) return fail(status.error());
  for (size_t i = 0; i < c.names.size(); ++i) {
    auto triangulated = LandmarkTriangulator::triangulate(c.names[i], c.clicks[i]);
    c.triangulated_world_mm.push_back(triangulated ? std::optional(triangulated.value()) : std::nullopt);
    c.triangulationError.push_back(triangulated.error());
  }
  return c;
}

/// Sum of squared reprojection errors (px^2) of all clicks.
double reprojectionCost(const Correspondences& c, const Eigen::Isometry3d& T_world_from_ct) {
  double cost = 0.0;
  for (size_t i = 0; i < c.names.size(); ++i) {
    const Eigen::Vector3d p_world_mm = T_world_from_ct * c.p_ct_mm[i];
    for (const auto& click : c.clicks[i]) cost += (click.camera.project(p_world_mm) - click.uv_px).squaredNorm();
  }
  return std::isfinite(cost) ? cost : std::numeric_limits<double>::infinity();
}

/// T_world_from_ct from SQPnP on the clicks of one view; nullopt if OpenCV finds no solution.
std::optional<Eigen::Isometry3d> pnpInView(const Correspondences& c, const std::string& view, const Camera& camera) {
  std::vector<cv::Point3d> objectPoints;
  std::vector<cv::Point2d> imagePoints;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const auto& p : c.p_ct_mm) centroid += p;
  centroid /= static_cast<double>(c.p_ct_mm.size());
  for (size_t i = 0; i < c.names.size(); ++i) {
    for (const auto& click : c.clicks[i]) {
      if (click.view != view) continue;
      const Eigen::Vector3d p = c.p_ct_mm[i] - centroid;  // centred for conditioning
      objectPoints.emplace_back(p.x(), p.y(), p.z());
      imagePoints.emplace_back(click.uv_px.x(), click.uv_px.y());
    }
  }
  if (objectPoints.size() < 4) return std::nullopt;
  const Eigen::Matrix3d K = camera.K();
  cv::Mat cameraMatrix(3, 3, CV_64F);
  for (int r = 0; r < 3; ++r)
    for (int col = 0; col < 3; ++col) cameraMatrix.at<double>(r, col) = K(r, col);
  cv::Mat rvec, tvec;
  try {
    if (!cv::solvePnP(objectPoints, imagePoints, cameraMatrix, cv::noArray(), rvec, tvec, false, cv::SOLVEPNP_SQPNP)) {
      return std::nullopt;
    }
  } catch (const cv::Exception&) {
    return std::nullopt;  // a degenerate view; other starts may still work
  }
  cv::Mat R;
  cv::Rodrigues(rvec, R);
  Eigen::Isometry3d T_camera_from_centred = Eigen::Isometry3d::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int col = 0; col < 3; ++col) T_camera_from_centred.linear()(r, col) = R.at<double>(r, col);
    T_camera_from_centred.translation()[r] = tvec.at<double>(r);
  }
  return camera.T_world_from_camera() * T_camera_from_centred * Eigen::Translation3d(-centroid);
}

/// T_world_from_ct fitting the CT points to the triangulated ones (Umeyama, no scale); nullopt with < 3 of them.
std::optional<Eigen::Isometry3d> rigidFitToTriangulated(const Correspondences& c) {
  std::vector<size_t> used;
  for (size_t i = 0; i < c.names.size(); ++i) {
    if (c.triangulated_world_mm[i]) used.push_back(i);
  }
  if (used.size() < 3) return std::nullopt;
  Eigen::Matrix3Xd src(3, used.size()), dst(3, used.size());
  for (size_t k = 0; k < used.size(); ++k) {
    src.col(k) = c.p_ct_mm[used[k]];
    dst.col(k) = *c.triangulated_world_mm[used[k]];
  }
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.matrix() = Eigen::umeyama(src, dst, false);
  return T;
}

/// Levenberg–Marquardt on the reprojection error of all clicks; the pose is updated by a small rotation about the
/// landmarks' centroid and a translation (both in the world frame).
Eigen::Isometry3d refineByReprojection(const Correspondences& c, Eigen::Isometry3d T) {
  using Vector6d = Eigen::Matrix<double, 6, 1>;
  using Matrix6d = Eigen::Matrix<double, 6, 6>;
  double cost = reprojectionCost(c, T);
  double damping = 1e-3;
  for (int iteration = 0; iteration < 200 && std::isfinite(cost) && cost > 0.0; ++iteration) {
    Eigen::Vector3d centre_world_mm = Eigen::Vector3d::Zero();
    for (const auto& p : c.p_ct_mm) centre_world_mm += T * p;
    centre_world_mm /= static_cast<double>(c.p_ct_mm.size());
    Matrix6d H = Matrix6d::Zero();
    Vector6d g = Vector6d::Zero();
    for (size_t i = 0; i < c.names.size(); ++i) {
      const Eigen::Vector3d p_world_mm = T * c.p_ct_mm[i];
      const Eigen::Vector3d q = p_world_mm - centre_world_mm;
      Eigen::Matrix<double, 3, 6> dp;  // d p_world / d(omega, v)
      dp << 0.0, q.z(), -q.y(), 1.0, 0.0, 0.0,  //
          -q.z(), 0.0, q.x(), 0.0, 1.0, 0.0,    //
          q.y(), -q.x(), 0.0, 0.0, 0.0, 1.0;
      for (const auto& click : c.clicks[i]) {
        Eigen::Matrix<double, 2, 3> Jp;
        const Eigen::Vector2d r = LandmarkTriangulator::projectWithJacobian(click.camera, p_world_mm, &Jp) - click.uv_px;
        const Eigen::Matrix<double, 2, 6> J = Jp * dp;
        H += J.transpose() * J;
        g += J.transpose() * r;
      }
    }
    bool accepted = false;
    while (!accepted && damping < 1e12) {
      Matrix6d A = H;
      A.diagonal() += damping * H.diagonal().cwiseMax(1e-12);
      const Vector6d step = -A.ldlt().solve(g);
      if (!step.allFinite()) {
        damping *= 10.0;
        continue;
      }
      const Eigen::Vector3d omega = step.head<3>();
      Eigen::Isometry3d delta = Eigen::Isometry3d::Identity();
      if (omega.norm() > 0.0) delta.linear() = Eigen::AngleAxisd(omega.norm(), omega.normalized()).toRotationMatrix();
      delta.translation() = centre_world_mm + step.tail<3>() - delta.linear() * centre_world_mm;
      const Eigen::Isometry3d candidate = delta * T;
      const double candidateCost = reprojectionCost(c, candidate);
      if (candidateCost < cost) {
        const bool tiny = omega.norm() < 1e-14 && step.tail<3>().norm() < 1e-11;
        T = candidate;
        const double previous = cost;
        cost = candidateCost;
        damping = std::max(damping / 3.0, 1e-9);
        accepted = true;
        if (tiny || previous - cost < 1e-15 * previous) return T;
      } else {
        damping *= 4.0;
      }
    }
    if (!accepted) break;  // no step lowers the cost: at the minimum to machine precision
  }
  return T;
}

Result<LandmarkPoseEstimate> finishEstimate(const Correspondences& c, const Eigen::Isometry3d& T_world_from_ct,
                                            std::string method) {
  LandmarkPoseEstimate estimate;
  estimate.T_world_from_ct = T_world_from_ct;
  estimate.method = std::move(method);
  double sumPx = 0.0, sumMm = 0.0;
  int countPx = 0, countMm = 0;
  for (size_t i = 0; i < c.names.size(); ++i) {
    const Eigen::Vector3d p_world_mm = T_world_from_ct * c.p_ct_mm[i];
    LandmarkResidual residual;
    residual.name = c.names[i];
    for (const auto& click : c.clicks[i]) {
      bool inFront = false;
      const double error_px = (click.camera.project(p_world_mm, &inFront) - click.uv_px).norm();
      if (!inFront) {
        return fail(fmt::format("the landmark solution places '{}' behind the X-ray source of view '{}'; check the "
                                "clicks and the view geometry",
                                c.names[i], click.view));
      }
      residual.reprojection_px[click.view] = error_px;
      sumPx += error_px * error_px;
      ++countPx;
    }
    residual.distance_mm = kNaN;
    if (c.triangulated_world_mm[i]) {
      residual.distance_mm = (p_world_mm - *c.triangulated_world_mm[i]).norm();
      sumMm += residual.distance_mm * residual.distance_mm;
      ++countMm;
    }
    estimate.residuals.push_back(std::move(residual));
  }
  estimate.rmsReprojection_px = std::sqrt(sumPx / countPx);
  estimate.rms3d_mm = countMm > 0 ? std::sqrt(sumMm / countMm) : kNaN;
  return estimate;
}

}  // namespace

Result<LandmarkPoseEstimate> LandmarkPoseEstimator::fromReprojection(const Landmarks& landmarks,
                                                                     const std::map<std::string, Camera>& cameras) {
  auto paired = pairLandmarks(landmarks, cameras);
  if (!paired) return fail(paired.error());
  const Correspondences& c = paired.value();
  std::vector<Eigen::Isometry3d> starts;
  std::set<std::string> clickedViews;
  for (const auto& clicks : c.clicks)
    for (const auto& click : clicks) clickedViews.insert(click.view);
  for (const auto& view : clickedViews) {
    if (auto T = pnpInView(c, view, cameras.at(view))) starts.push_back(*T);
  }
  if (auto T = rigidFitToTriangulated(c)) starts.push_back(*T);
  if (starts.empty()) {
    return fail("no starting pose: no view has 4 or more landmarks clicked and fewer than 3 landmarks are clicked in "
                "two views; click at least 4 landmarks in one view");
  }
  const Eigen::Isometry3d* best = &starts.front();
  for (const auto& T : starts) {
    if (reprojectionCost(c, T) < reprojectionCost(c, *best)) best = &T;
  }
  const Eigen::Isometry3d refined = refineByReprojection(c, *best);
  return finishEstimate(c, refined, clickedViews.size() == 1 ? "pnp" : "joint-reprojection");
}

Result<LandmarkPoseEstimate> LandmarkPoseEstimator::fromTriangulation(const Landmarks& landmarks,
                                                                      const std::map<std::string, Camera>& cameras) {
  auto paired = pairLandmarks(landmarks, cameras);
  if (!paired) return fail(paired.error());
  const Correspondences& c = paired.value();
  for (size_t i = 0; i < c.names.size(); ++i) {
    if (!c.triangulated_world_mm[i]) return fail(c.triangulationError[i]);
  }
  const auto T = rigidFitToTriangulated(c);  // >= 4 triangulated points by now
  return finishEstimate(c, *T, "triangulation");
}

}  // namespace fct
