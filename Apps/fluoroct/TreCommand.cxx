// fluoroct tre: the error of an estimated bone pose against the true one (PoseErrorMetrics): sTRE mean and max over
// the bone surface, mTRE over the bone's bounding box, rotation and translation error.
#include <fmt/core.h>

#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "CliSupport.h"
#include "Evaluation/PoseErrorMetrics.h"
#include "IO/Project/PoseFile.h"
#include "IO/Volume/CtLoader.h"

namespace fct::cli {

namespace {

struct TreOptions {
  std::string ct, truth, estimate;
  bool json = false;
  double boneThreshold_hu = BoneSurface::kDefaultThreshold_hu;
};

int runTre(const TreOptions& o) {
  auto truth = PoseFile::read(o.truth);
  if (!truth) return reportError("--truth: " + truth.error());
  // The estimate may be a `fluoroct register` RESULT.json: its other keys are expected, so no warnings for them.
  auto estimate = PoseFile::read(o.estimate);
  if (!estimate) return reportError("--estimate: " + estimate.error());
  auto ct = CtLoader::load(o.ct);
  if (!ct) return reportError(ct.error());
  auto metrics = PoseErrorMetrics::create(ct.value(), o.boneThreshold_hu);
  if (!metrics) return reportError(fmt::format("{}; lower --bone-threshold-hu", metrics.error()));
  const PoseError e = metrics.value().measure(estimate.value(), truth.value());
  if (o.json) {
    const nlohmann::ordered_json json{{"stre_mean_mm", e.streMean_mm},
                                      {"stre_max_mm", e.streMax_mm},
                                      {"mtre_mm", e.mtre_mm},
                                      {"rotation_deg", e.rotation_deg},
                                      {"translation_mm", e.translation_mm}};
    fmt::print("{}\n", json.dump(2));
    return 0;
  }
  fmt::print("sTRE       mean {:.3f} mm, max {:.3f} mm ({} bone-surface points at {} HU)\n", e.streMean_mm,
             e.streMax_mm, metrics.value().surface().points_ct_mm().size(), o.boneThreshold_hu);
  fmt::print("mTRE       {:.3f} mm ({} grid points over the bone's bounding box)\n", e.mtre_mm,
             metrics.value().regionPoints_ct_mm().size());
  fmt::print("rotation   {:.3f} deg\ntranslation {:.3f} mm at the bone centre\n", e.rotation_deg, e.translation_mm);
  fmt::print("success    {} (sTRE mean < {} mm)\n", PoseErrorMetrics::isSuccess(e) ? "yes" : "no",
             PoseErrorMetrics::kSuccessThreshold_mm);
  return 0;
}

}  // namespace

void registerTreCommand(CLI::App& app, CommandAction& action) {
  auto options = std::make_shared<TreOptions>();
  CLI::App* command = app.add_subcommand(
      "tre", "Pose error of an estimate against the truth: sTRE mean/max (bone surface), mTRE (bone bounding box), "
             "rotation (deg) and translation (mm at the bone centre)");
  command->add_option("--ct", options->ct, "CT volume or DICOM series folder (gives the bone surface)")->required();
  command->add_option("--truth", options->truth, "True pose file {\"T_world_from_ct\": 4x4}")->required();
  command->add_option("--estimate", options->estimate,
                      "Estimated pose file, or a `fluoroct register` RESULT.json (its T_world_from_ct)")
      ->required();
  command->add_flag("--json", options->json,
                    "Print JSON {stre_mean_mm, stre_max_mm, mtre_mm, rotation_deg, translation_mm}");
  command->add_option("--bone-threshold-hu", options->boneThreshold_hu, "Bone surface iso-value in HU")
      ->capture_default_str();
  command->callback([&action, options] { action = [options] { return runTre(*options); }; });
}

}  // namespace fct::cli
