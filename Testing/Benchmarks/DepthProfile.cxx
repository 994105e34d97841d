// Depth profile: how well one view's tracking similarity sees the depth (the bone's motion along the viewing ray).
// For a single-view case (a view file with an "image" and its true pose) and the CineTracker frame stage (VLNC on the
// frame's dynamic ROIs at the tracking level, rendered with --frame-drr on the CT coarsened to that level), it prints
//   * with --scan-mm S: the similarity at the truth moved across the ray (along the detector's columns) in 21 steps of
//     S mm, the other parameters fixed: a rough curve (box voxels) stops a local search early;
//   * for every --depths D: the similarity at the truth moved D mm along the ray (source to the bone centre) with the
//     other five parameters fixed ("fixed"), and maximized over them by BOBYQA (NLopt, from the moved pose; "best"):
//     the profile a search along the coupled valley sees. Its peak is where a perfect single-plane search ends.
//
// Usage: fluoroct_depth_profile --ct CT --views VIEWS.json --pose TRUTH.json [--level L] [--roi-fraction F]
//                               [--frame-drr raycast|siddon] [--depths D,D,...] [--scan-mm S]
#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <nlopt.h>

#include <cmath>
#include <string>
#include <vector>

#include "Drr/DrrRendererFactory.h"
#include "IO/Project/PoseFile.h"
#include "IO/Volume/CtLoader.h"
#include "Registration/RegistrationObjective.h"
#include "Registration/RegistrationViewLoader.h"
#include "Tracking/CineTracker.h"

namespace {

/// The objective and the frame of the viewing ray at the true pose.
struct Profile {
  fct::RegistrationObjective* objective = nullptr;
  Eigen::Isometry3d T_truth = Eigen::Isometry3d::Identity();
  Eigen::Vector3d centre_world_mm = Eigen::Vector3d::Zero();
  Eigen::Vector3d across1 = Eigen::Vector3d::Zero();  ///< across the ray, along the detector's columns
  Eigen::Vector3d across2 = Eigen::Vector3d::Zero();
  Eigen::Vector3d ray = Eigen::Vector3d::Zero();      ///< source to the bone centre
  double depth_mm = 0.0;
  long evaluations = 0;
};

/// The truth moved depth_mm along the ray, turned by p[0..2] deg about the bone centre and moved p[3], p[4] mm across.
Eigen::Isometry3d poseAt(const Profile& profile, const double* p) {
  const Eigen::Vector3d rotation_rad = Eigen::Vector3d(p[0], p[1], p[2]) * M_PI / 180.0;
  Eigen::Isometry3d turn = Eigen::Isometry3d::Identity();
  if (rotation_rad.norm() > 0.0) {
    turn.linear() = Eigen::AngleAxisd(rotation_rad.norm(), rotation_rad.normalized()).matrix();
  }
  Eigen::Isometry3d T = Eigen::Translation3d(profile.centre_world_mm) * turn *
                        Eigen::Translation3d(-profile.centre_world_mm) * profile.T_truth;
  T.pretranslate(profile.depth_mm * profile.ray + p[3] * profile.across1 + p[4] * profile.across2);
  return T;
}

/// NLopt objective: the negated similarity (2 on a rendering error).
double negatedSimilarity(unsigned, const double* p, double*, void* data) {
  Profile& profile = *static_cast<Profile*>(data);
  ++profile.evaluations;
  auto similarity = profile.objective->similarity(poseAt(profile, p));
  return similarity ? -similarity.value() : 2.0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Similarity of the tracking frame stage along one view's viewing ray, around a known pose"};
  std::string ctPath, viewsPath, posePath, frameDrr = "raycast";
  std::vector<double> depths_mm{-6.0, -4.0, -2.0, -1.0, 0.0, 1.0, 2.0, 4.0, 6.0};
  double scan_mm = 0.0;
  fct::CineTrackerOptions trackerOptions;
  app.add_option("--ct", ctPath, "CT volume or DICOM folder")->required();
  app.add_option("--views", viewsPath, "View file with one view and its image")->required();
  app.add_option("--pose", posePath, "True pose file {\"T_world_from_ct\": 4x4}")->required();
  app.add_option("--level", trackerOptions.level, "Pyramid level (-1: the tracker's automatic level)")
      ->capture_default_str();
  app.add_option("--roi-fraction", trackerOptions.roiFraction, "ROI fraction of the frame stage")
      ->capture_default_str();
  app.add_option("--frame-drr", frameDrr, "raycast or siddon")->capture_default_str();
  app.add_option("--depths", depths_mm, "Depth offsets along the ray, mm, comma-separated")
      ->delimiter(',')
      ->capture_default_str();
  app.add_option("--scan-mm", scan_mm, "Also scan across the ray in 21 steps of this many mm (0: no scan)");
  CLI11_PARSE(app, argc, argv);

  auto method = fct::DrrRendererFactory::parseMethod(frameDrr);
  auto ct = fct::CtLoader::load(ctPath);
  auto views = fct::RegistrationViewLoader::load(viewsPath);
  auto truth = fct::PoseFile::read(posePath);
  for (const std::string& error : {method ? "" : method.error(), ct ? "" : ct.error(), views ? "" : views.error(),
                                   truth ? "" : truth.error()}) {
    if (!error.empty()) return fmt::print(stderr, "error: {}\n", error), 2;
  }
  if (views.value().size() != 1) return fmt::print(stderr, "error: give a view file with one view\n"), 2;
  trackerOptions.frameDrr = method.value();
  trackerOptions.firstFrame.schedule = fct::RegistrationSchedule::builtin("fast").value();
  auto registrationCase = fct::RegistrationCase::create(ct.value(), views.value());
  if (!registrationCase) return fmt::print(stderr, "error: {}\n", registrationCase.error()), 2;
  auto tracker = fct::CineTracker::create(registrationCase.value(), trackerOptions);
  if (!tracker) return fmt::print(stderr, "error: {}\n", tracker.error()), 2;
  const fct::RegistrationStage& stage = tracker.value().frameSchedule().stages.front();
  auto objective = fct::RegistrationObjective::create(registrationCase.value(), stage, false, truth.value(),
                                                      truth.value());
  if (!objective) return fmt::print(stderr, "error: {}\n", objective.error()), 2;

  Profile profile;
  profile.objective = &objective.value();
  profile.T_truth = truth.value();
  profile.centre_world_mm = truth.value() * registrationCase.value().rotationCentre_ct_mm();
  const fct::Camera& camera = registrationCase.value().camera(0);
  profile.ray = (profile.centre_world_mm - camera.sourcePosition_world_mm()).normalized();
  const Eigen::Vector3d columns = camera.T_world_from_camera().linear().col(0);
  profile.across1 = (columns - columns.dot(profile.ray) * profile.ray).normalized();
  profile.across2 = profile.ray.cross(profile.across1);
  const std::string step =
      stage.drrStep_voxels > 0.0 ? fmt::format(" (a sample every {:g} coarse voxels)", stage.drrStep_voxels) : "";
  fmt::print("frame stage: VLNC on {:.0f} % ROIs at level {}, {} DRRs{}\n", 100.0 * stage.pixels.targetFraction,
             stage.level, frameDrr, step);

  if (scan_mm > 0.0) {
    fmt::print("across the ray (mm: similarity):");
    for (int i = -10; i <= 10; ++i) {
      double p[5] = {0.0, 0.0, 0.0, scan_mm * i, 0.0};
      fmt::print(" {:+.2f}: {:.5f}", scan_mm * i, -negatedSimilarity(0, p, nullptr, &profile));
    }
    fmt::print("\n");
  }
  for (const double depth_mm : depths_mm) {
    profile.depth_mm = depth_mm;
    profile.evaluations = 0;
    double p[5] = {0.0, 0.0, 0.0, 0.0, 0.0};
    const double fixed = -negatedSimilarity(0, p, nullptr, &profile);
    nlopt_opt opt = nlopt_create(NLOPT_LN_BOBYQA, 5);
    nlopt_set_min_objective(opt, negatedSimilarity, &profile);
    const double step[5] = {1.0, 1.0, 1.0, 1.0, 1.0};
    const double lower[5] = {-8.0, -8.0, -8.0, -10.0, -10.0}, upper[5] = {8.0, 8.0, 8.0, 10.0, 10.0};
    nlopt_set_initial_step(opt, step);
    nlopt_set_lower_bounds(opt, lower);
    nlopt_set_upper_bounds(opt, upper);
    nlopt_set_xtol_abs1(opt, 0.005);
    nlopt_set_maxeval(opt, 600);
    double best = 0.0;
    nlopt_optimize(opt, p, &best);
    nlopt_destroy(opt);
    fmt::print("depth {:+6.2f} mm: fixed {:.5f}  best {:.5f} at rotation ({:+.2f}, {:+.2f}, {:+.2f}) deg, across "
               "({:+.2f}, {:+.2f}) mm, {} evaluations\n",
               depth_mm, fixed, -best, p[0], p[1], p[2], p[3], p[4], profile.evaluations);
  }
  return 0;
}
