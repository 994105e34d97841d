// fluoroct pose: writes a pose file: a reference pose moved by a given offset about the bone centre, or by a random
// offset at a chosen mean bone-surface distance (start poses for known-truth cases).
#include <fmt/core.h>

#include <array>
#include <memory>
#include <string>

#include "CliSupport.h"
#include "Evaluation/PoseOffset.h"
#include "Image/BoneSurface.h"
#include "IO/Project/PoseFile.h"
#include "IO/Volume/CtLoader.h"

namespace fct::cli {

namespace {

struct PoseCommandOptions {
  std::string ct, from, out;
  std::array<double, 3> rotation_deg{0.0, 0.0, 0.0};
  std::array<double, 3> translation_mm{0.0, 0.0, 0.0};
  double randomOffset_mm = -1.0;  ///< < 0: no random offset
  std::uint32_t seed = 1;
  double boneThreshold_hu = BoneSurface::kDefaultThreshold_hu;
};

int runPose(const PoseCommandOptions& options) {
  Eigen::Isometry3d T_reference = Eigen::Isometry3d::Identity();
  if (!options.from.empty()) {
    const auto from = PoseFile::read(options.from);
    if (!from.ok()) return reportError(from.error());
    T_reference = from.value();
  }
  const auto ct = CtLoader::load(options.ct);
  if (!ct.ok()) return reportError(ct.error());
  const auto bone = BoneSurface::extract(ct.value(), options.boneThreshold_hu);
  if (!bone.ok()) return reportError(fmt::format("{}; lower --bone-threshold-hu", bone.error()));

  const PoseParameters offset{Eigen::Vector3d(options.rotation_deg.data()),
                              Eigen::Vector3d(options.translation_mm.data())};
  if (!offset.asVector().allFinite()) return reportError("--rotate-deg and --translate-mm must be finite numbers");
  Eigen::Isometry3d T_pose = PoseOffset::apply(bone.value(), T_reference, offset);
  if (options.randomOffset_mm >= 0.0) {
    const auto random = PoseOffset::randomAtSurfaceDistance(bone.value(), T_pose, options.randomOffset_mm, options.seed);
    if (!random.ok()) return reportError(random.error());
    T_pose = random.value();
  }
  const Status written = PoseFile::write(T_pose, options.out);
  if (!written.ok()) return reportError(written.error());
  fmt::print("wrote {}: mean bone-surface distance from the reference pose {:.3f} mm (max {:.3f} mm), {} surface "
             "points at {} HU\n",
             options.out, bone.value().meanDistance_mm(T_pose, T_reference),
             bone.value().maxDistance_mm(T_pose, T_reference), bone.value().points_ct_mm().size(),
             options.boneThreshold_hu);
  return 0;
}

}  // namespace

void registerPoseCommand(CLI::App& app, CommandAction& action) {
  auto options = std::make_shared<PoseCommandOptions>();
  CLI::App* command = app.add_subcommand(
      "pose", "Write a pose file: a reference pose moved about the bone centre by a given offset and/or a random "
              "offset at a given mean bone-surface distance");
  command->add_option("--ct", options->ct, "CT (DICOM folder or volume file) whose bone defines centre and surface")
      ->required();
  command->add_option("--out", options->out, "Output pose file (.json)")->required();
  command->add_option("--from", options->from, "Reference pose file (default: identity)");
  command->add_option("--rotate-deg", options->rotation_deg,
                      "Rotation rx ry rz in degrees about the bone centre (R = Rz Ry Rx, world axes)");
  command->add_option("--translate-mm", options->translation_mm, "Translation tx ty tz in world mm (LPS)");
  command->add_option("--random-offset-mm", options->randomOffset_mm,
                      "Then move by a random rotation and translation whose mean bone-surface distance is this many mm");
  command->add_option("--seed", options->seed, "Seed of the random offset")->capture_default_str();
  command->add_option("--bone-threshold-hu", options->boneThreshold_hu, "Bone threshold of the surface in HU")
      ->capture_default_str();
  command->callback([&action, options] { action = [options] { return runPose(*options); }; });
}

}  // namespace fct::cli
