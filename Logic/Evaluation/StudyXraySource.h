#pragma once
// StudyXraySource: where a study's test X-rays and registration CTs come from (one seam, so the simulator can be
// swapped without touching the studies). X-rays are always rendered from the ORIGINAL CT at the true pose, as a
// continuous patient (its cubic B-spline interpolant, continued beyond the CT's end faces) with a scatter haze and,
// when asked, K-wires and screws that are not in the CT; the registration CT of the "realistic" and "bad" scenarios
// is the original resampled to a coarser slice spacing.

#include <Eigen/Geometry>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "Base/Result.h"
#include "Image/Volume.h"
#include "Image/XrayImage.h"
#include "IO/Project/ViewFile.h"
#include "Registration/RegistrationView.h"
#include "Simulation/FluoroscopySimulator.h"

namespace fct {

/// Makes the images and CTs of study trials.
class StudyXraySource {
 public:
  /// One line naming the forward model in use, for reports.
  static std::string description();
  /// The simulator settings of every study X-ray (patient, beam, haze, detector), with 2 K-wires and 2 screws when
  /// `foreignObjects`; simulate() adds the seed.
  static FluoroscopyOptions forwardModel(bool foreignObjects);
  /// Simulated X-rays of `ct` (LPS mm) at T_world_from_ct for every view (detector sizes from the cameras), view n
  /// with noise seed `seed + n`, with foreign objects (placed by `seed`) when `foreignObjects`. Fails, naming the
  /// view, on a rendering or simulation error.
  static Result<std::vector<RegistrationView>> simulate(const Volume& ct, const std::vector<ViewSpec>& views,
                                                        const Eigen::Isometry3d& T_world_from_ct, std::uint32_t seed,
                                                        bool foreignObjects);
  /// Receives frame `frame`'s X-rays (one per view, in view order); an error stops simulateSequence with it.
  using FrameSink = std::function<Status(int frame, std::vector<XrayImage> xrays)>;
  /// A cine sequence of `ct` (LPS mm): frame k's X-rays of every view at poses_world_from_ct[k], each frame and view
  /// with its own noise (seeds from `seed`), passed to `onFrame` as each frame is rendered; with `foreignObjects`,
  /// K-wires and screws placed at the first pose that stay fixed in the world while the bone moves. Fails, naming
  /// frame and view, on a simulation error, or with the first error of `onFrame`.
  static Status simulateSequence(const Volume& ct, const std::vector<ViewSpec>& views,
                                 const std::vector<Eigen::Isometry3d>& poses_world_from_ct, std::uint32_t seed,
                                 bool foreignObjects, const FrameSink& onFrame);
  /// The CT registration sees: `ct` resampled to `sliceSpacing_mm` along its slice axis with the matching
  /// slice-thickness blur (CtSliceDegrader), or `ct` itself when effectiveSliceSpacing_mm() is 0. Fails on a negative
  /// or non-finite spacing or a resampling error.
  static Result<Volume> registrationCt(const Volume& ct, double sliceSpacing_mm);
  /// The slice spacing registrationCt() resamples to: `sliceSpacing_mm` if it is above the CT's own slice spacing,
  /// else 0 (the original CT is used: its slices are already that coarse, or 0 was asked).
  static double effectiveSliceSpacing_mm(const Volume& ct, double sliceSpacing_mm);
};

}  // namespace fct
