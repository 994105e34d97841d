#include "InitialPoseInput.h"

#include <fmt/core.h>
#include <fmt/ranges.h>

#include <cmath>
#include <map>

#include "CliSupport.h"
#include "InitialPose/LandmarkPoseEstimator.h"
#include "IO/Project/LandmarkPairFile.h"
#include "SlicerModule.h"

namespace fct::cli {

namespace {

/// The residuals of a landmark estimate as RESULT.json lists them.
nlohmann::ordered_json residualsJson(const LandmarkPoseEstimate& e) {
  nlohmann::ordered_json residuals = nlohmann::ordered_json::array();
  for (const LandmarkResidual& r : e.residuals) {
    nlohmann::ordered_json perView = nlohmann::ordered_json::object();
    for (const auto& [viewName, px] : r.reprojection_px) perView[viewName] = px;
    nlohmann::ordered_json entry{{"name", r.name}, {"reprojection_px", perView}};
    if (std::isfinite(r.distance_mm)) entry["distance_mm"] = r.distance_mm;
    residuals.push_back(std::move(entry));
  }
  return residuals;
}

/// The initial pose estimated from the landmark pair file `path` with the views' cameras.
Result<InitialPose> poseFromLandmarks(const std::string& path, const std::vector<RegistrationView>& views) {
  auto pairs = LandmarkPairFile::read(path);
  if (!pairs) return fail("--landmarks: " + pairs.error());
  printWarnings(pairs.warnings());
  const LandmarkPairSet& set = pairs.value();
  std::map<std::string, Camera> cameras;
  for (const RegistrationView& view : views) cameras.emplace(view.name, view.camera);
  for (const auto& [viewName, clicks] : set.landmarks.imageByView) {
    if (!cameras.count(viewName)) {
      std::vector<std::string> names;
      for (const RegistrationView& view : views) names.push_back(view.name);
      return fail(fmt::format("{}: landmarks are clicked in view '{}', which the view file does not have (views: {}); "
                              "the landmark and view files must name the same views",
                              set.imageFile.string(), viewName, fmt::join(names, ", ")));
    }
  }
  auto estimate = set.method == LandmarkPoseMethod::Triangulation
                      ? LandmarkPoseEstimator::fromTriangulation(set.landmarks, cameras)
                      : LandmarkPoseEstimator::fromReprojection(set.landmarks, cameras);
  if (!estimate) return fail("initial pose from landmarks: " + estimate.error());
  const LandmarkPoseEstimate& e = estimate.value();
  nlohmann::ordered_json source{{"source", "landmarks"},
                                {"path", path},
                                {"method", e.method},
                                {"rms_reprojection_px", e.rmsReprojection_px}};
  if (std::isfinite(e.rms3d_mm)) source["rms_3d_mm"] = e.rms3d_mm;
  source["residuals"] = residualsJson(e);
  return InitialPose{e.T_world_from_ct, std::move(source)};
}

}  // namespace

Status checkInitialPoseFlags(const std::string& init, const std::string& landmarks) {
  if (init.empty() == landmarks.empty()) {
    return fail("give the initial pose with exactly one of --init POSE.json|POSE.tfm or --landmarks LM.json");
  }
  return Ok{};
}

Result<InitialPose> readInitialPose(const std::string& init, const std::string& landmarks,
                                    const std::vector<RegistrationView>& views) {
  if (Status flags = checkInitialPoseFlags(init, landmarks); !flags) return fail(flags.error());
  if (init.empty()) return poseFromLandmarks(landmarks, views);
  auto pose = readPoseOrTransform(init);
  if (!pose) return fail("--init: " + pose.error());
  return InitialPose{pose.value(), nlohmann::ordered_json{{"source", "pose file"}, {"path", init}}};
}

}  // namespace fct::cli
