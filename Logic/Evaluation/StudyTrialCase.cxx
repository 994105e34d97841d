#include "Evaluation/StudyTrialCase.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>

#include "Evaluation/PoseErrorMetrics.h"
#include "Evaluation/StudyCatalog.h"
#include "Evaluation/StudyXraySource.h"
#include "IO/Project/PoseFile.h"
#include "IO/Volume/VolumeFileIO.h"
#include "Registration/RegistrationCase.h"
#include "Simulation/FluoroscopySimulator.h"
#include "Simulation/StandardViews.h"

namespace fct {

namespace {

/// The condition named `name`, or an error listing the study's conditions.
Result<const StudyCondition*> findCondition(const StudyDefinition& study, const std::string& name) {
  std::vector<std::string> names;
  for (const StudyCondition& c : study.conditions) {
    if (c.name == name) return &c;
    names.push_back(c.name);
  }
  return fail(fmt::format("study '{}' has no condition '{}'; its conditions are: {}", study.name, name,
                          fmt::join(names, ", ")));
}

}  // namespace

Result<StudyTrialCaseFiles> StudyTrialCase::write(const StudyDefinition& study, const std::vector<StudyCt>& cts,
                                                  const std::string& conditionName, int trial,
                                                  const std::filesystem::path& ctPath,
                                                  const std::filesystem::path& folder) {
  auto found = findCondition(study, conditionName);
  if (!found) return fail(found.error());
  const StudyCondition& c = *found.value();
  if (trial < 0 || trial >= c.trials) {
    return fail(fmt::format("condition '{}' has trials 0 to {}, not {}", c.name, c.trials - 1, trial));
  }
  const auto ct = std::find_if(cts.begin(), cts.end(), [&](const StudyCt& s) { return s.label == c.ct; });
  if (ct == cts.end()) return fail(fmt::format("condition '{}': no CT labelled '{}' was given", c.name, c.ct));

  auto metrics = PoseErrorMetrics::create(ct->volume);
  if (!metrics) return fail(fmt::format("CT '{}': {}", c.ct, metrics.error()));
  const BoneSurface& bone = metrics.value().surface();
  const std::uint32_t seed = study.setup.seed + static_cast<std::uint32_t>(trial);
  const Eigen::Isometry3d T_truth = study.setup.xraysPerTrial ? StudyRunner::trialTruthPose(bone, seed)
                                                               : StudyRunner::truthPose(bone);
  StandardViewOptions viewOptions = study.setup.detector;
  viewOptions.count = c.viewCount;
  auto views = StandardViews::build(Eigen::Vector3d::Zero(), viewOptions);
  if (!views) return fail(views.error());
  std::vector<Camera> cameras;
  for (const ViewSpec& view : views.value()) cameras.push_back(view.camera);
  double initialTarget_mm = 0.0;
  auto start = StudyRunner::startPose(c, bone, T_truth, cameras, seed, initialTarget_mm);
  if (!start) return fail("start pose: " + start.error());
  auto registrationCt = StudyXraySource::registrationCt(ct->volume, c.sliceSpacing_mm);
  if (!registrationCt) return fail(fmt::format("CT '{}': {}", c.ct, registrationCt.error()));

  FluoroscopyOptions forward = StudyXraySource::forwardModel(StudyCatalog::scenarioHasForeignObjects(c.scenario));
  forward.seed = study.setup.xraysPerTrial ? StudyRunner::trialXraySeed(seed) : study.setup.seed;
  auto simulated = FluoroscopySimulator::writeCase(ct->volume, views.value(), T_truth, forward, folder,
                                                      ctPath.empty() ? c.ct : ctPath.string());
  if (!simulated) return fail(simulated.error());

  StudyTrialCaseFiles files;
  files.viewFile = simulated.value().viewFile;
  files.truthFile = simulated.value().poseFile;
  const std::filesystem::path written = files.viewFile.parent_path();  // the folder, as absolute as the views' paths
  files.startFile = written / "start_pose.json";
  if (Status written = PoseFile::write(start.value(), files.startFile); !written) return fail(written.error());
  files.registrationCt = ctPath;
  if (ctPath.empty() || StudyXraySource::effectiveSliceSpacing_mm(ct->volume, c.sliceSpacing_mm) > 0.0) {
    files.registrationCt = written / "ct_registration.nrrd";
    files.ctWritten = true;
    if (Status written = VolumeFileIO::write(registrationCt.value(), files.registrationCt); !written) {
      return fail(written.error());
    }
  }
  files.cutFaceMargin_mm = RegistrationCaseOptions::kDefaultCutFaceMargin_mm;
  files.initialStre_mm = metrics.value().measure(start.value(), T_truth).streMean_mm;
  return files;
}

}  // namespace fct
