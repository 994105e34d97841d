#include "Registration/RotationSweep.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include <tbb/parallel_for.h>

#include "Geometry/RigidPose.h"
#include "Registration/ProjectionShiftAligner.h"

namespace fct {

namespace {

/// A grid pose before and after its shift alignment.
struct GridPose {
  Eigen::Isometry3d T_world_from_ct;
  double similarity = 0.0;
};

/// T rotated by the rotation vector `rotation_deg` (world axes) about the world point `centre_world_mm`.
Eigen::Isometry3d rotatedAbout(const Eigen::Isometry3d& T, const Eigen::Vector3d& rotation_deg,
                               const Eigen::Vector3d& centre_world_mm) {
  const double angle_rad = rotation_deg.norm() * M_PI / 180.0;
  const Eigen::AngleAxisd rotation(angle_rad, rotation_deg.normalized());
  return Eigen::Translation3d(centre_world_mm) * rotation * Eigen::Translation3d(-centre_world_mm) * T;
}

}  // namespace

std::vector<Eigen::Vector3d> RotationSweep::offsets_deg(double max_deg, double step_deg) {
  std::vector<Eigen::Vector3d> out;
  if (!(step_deg > 0.0) || !(max_deg >= step_deg)) return out;
  const int n = static_cast<int>(std::floor(max_deg / step_deg));
  for (int i = -n; i <= n; ++i) {
    for (int j = -n; j <= n; ++j) {
      for (int k = -n; k <= n; ++k) {
        const Eigen::Vector3d r = step_deg * Eigen::Vector3d(i, j, k);
        if ((i != 0 || j != 0 || k != 0) && r.norm() <= max_deg + 1e-9) out.push_back(r);
      }
    }
  }
  return out;
}

int RotationSweep::roughAlignmentHalvings(const RegistrationCase& registrationCase, int level) {
  int shorterSide_px = std::numeric_limits<int>::max();
  for (std::size_t v = 0; v < registrationCase.viewCount(); ++v) {
    const FloatImage& image = registrationCase.prepared(v).pyramid.level(level).image;
    shorterSide_px = std::min({shorterSide_px, image.cols, image.rows});
  }
  int halvings = 0;
  while (halvings < kRoughAlignmentMaxHalvings && (shorterSide_px >> (halvings + 1)) >= kRoughAlignmentMinSide_px) {
    ++halvings;
  }
  return halvings;
}

Result<std::vector<RotationSweepCandidate>> RotationSweep::run(RegistrationCase& registrationCase,
                                                               RegistrationObjective& gridObjective,
                                                               RegistrationObjective& objective,
                                                               const RotationSweepSpec& spec, int level,
                                                               const PoseVector& start, double startSimilarity) {
  const Eigen::Isometry3d T_start = registrationCase.poseTransform(start);
  const Eigen::Vector3d centre_world_mm = T_start * registrationCase.rotationCentre_ct_mm();
  std::vector<Eigen::Isometry3d> poses{T_start};  // the start's own rotation too: a far start may be off only in place
  for (const Eigen::Vector3d& r_deg : offsets_deg(spec.maxRotation_deg, spec.step_deg)) {
    poses.push_back(rotatedAbout(T_start, r_deg, centre_world_mm));
  }
  // A far start is off in translation too: each rotation is judged where a rough 2D alignment puts it. The alignments
  // run side by side; the first runs alone so that the level's renderers exist before the others look them up (every
  // grid pose keeps the start's bone centre, so they all use the same coarsened CT).
  const int halvings = roughAlignmentHalvings(registrationCase, level);
  std::vector<std::optional<Result<ShiftAlignment>>> rough(poses.size());
  const auto alignRoughly = [&](std::size_t i) {
    rough[i] = ProjectionShiftAligner::align(registrationCase, poses[i], level, 0.5, 0.2, halvings);
  };
  alignRoughly(0);
  if (!*rough[0]) return fail(rough[0]->error());
  tbb::parallel_for(std::size_t{1}, poses.size(), alignRoughly);
  std::vector<GridPose> grid;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    if (!*rough[i]) return fail(rough[i]->error());
    const Eigen::Isometry3d& T = rough[i]->value().T_world_from_ct;
    auto similarity = gridObjective.similarity(T);
    if (!similarity) return fail(similarity.error());
    grid.push_back({T, similarity.value()});
  }
  const auto better = [](const GridPose& a, const GridPose& b) { return a.similarity > b.similarity; };
  const std::size_t aligned = std::min(grid.size(), static_cast<std::size_t>(spec.aligned));
  std::partial_sort(grid.begin(), grid.begin() + static_cast<std::ptrdiff_t>(aligned), grid.end(), better);
  grid.resize(aligned);
  for (GridPose& pose : grid) {
    auto unshifted = objective.similarity(pose.T_world_from_ct);
    if (!unshifted) return fail(unshifted.error());
    pose.similarity = unshifted.value();
    auto shifted =
        ProjectionShiftAligner::align(registrationCase, pose.T_world_from_ct, level, kFineAlignmentShiftFraction);
    if (!shifted) return fail(shifted.error());
    auto similarity = objective.similarity(shifted.value().T_world_from_ct);
    if (!similarity) return fail(similarity.error());
    if (similarity.value() > pose.similarity) {
      pose.T_world_from_ct = shifted.value().T_world_from_ct;
      pose.similarity = similarity.value();
    }
  }
  std::stable_sort(grid.begin(), grid.end(), better);
  std::vector<RotationSweepCandidate> out;
  for (const GridPose& pose : grid) {
    if (!(pose.similarity > startSimilarity) || static_cast<int>(out.size()) >= spec.seeds) break;
    auto params = RigidPose::fromTransform(pose.T_world_from_ct, registrationCase.rotationCentre_ct_mm());
    if (!params) return fail(params.error());
    out.push_back({params.value().asVector(), pose.similarity});
  }
  return out;
}

}  // namespace fct
