#pragma once
// Known-truth fluoroscopy sequences for the tracking tests and benchmark: the bone moves smoothly about its centroid
// (a sine in every pose parameter, amplitudes in deg and mm), standard C-arm views (AP, lateral) around the world
// origin, and every frame rendered by the physical simulator (FluoroscopySimulator: polychromatic beam, noise), not by
// the registration's DRR.

#include <Eigen/Geometry>

#include <cmath>
#include <cstdint>
#include <vector>

#include "Base/Result.h"
#include "Geometry/RigidPose.h"
#include "Image/BoneSurface.h"
#include "Image/Volume.h"
#include "Registration/RegistrationView.h"
#include "Simulation/FluoroscopySimulator.h"
#include "Simulation/StandardViews.h"

namespace fct::test {

/// Settings of a simulated sequence.
struct SequenceOptions {
  int viewCount = 1;                 ///< 1 = single-plane (AP), 2 = biplane (AP, lateral)
  int size_px = 128;                 ///< square detector side
  double pixelSpacing_mm = 2.4;      ///< detector pixel size
  double sourceToIsocentre_mm = 700.0;
  double sourceToDetector_mm = 1000.0;
  int frames = 6;
  double amplitude_deg = 3.0;        ///< rotation amplitude of the sine motion (each axis)
  double amplitude_mm = 4.0;         ///< translation amplitude (each axis)
  double period_frames = 30.0;       ///< period of the sine motion
  double photonsPerPixel = 20000.0;  ///< quantum noise of the simulator (0 = noiseless)
  std::uint32_t seed = 5;
};

/// Views (frame 0's images), every frame's images per view, and the true pose of every frame.
struct SimulatedSequence {
  std::vector<RegistrationView> views;          ///< with frame 0's images
  std::vector<std::vector<XrayImage>> frames;   ///< frames[f][v]
  std::vector<Eigen::Isometry3d> T_truth;       ///< per frame (CT mm -> world mm, LPS)
  Eigen::Vector3d centre_ct_mm = Eigen::Vector3d::Zero();  ///< the bone centroid the motion turns about
};

/// The true pose of frame f: the bone centroid near the world origin (the isocentre), turned and moved by a sine.
inline Eigen::Isometry3d sequencePose(const Eigen::Vector3d& centre_ct_mm, const SequenceOptions& o, int f) {
  const double phase = 2.0 * M_PI * f / o.period_frames;
  PoseParameters p;
  p.rotation_deg = o.amplitude_deg * Eigen::Vector3d(std::sin(phase), std::sin(phase + 1.0), std::sin(phase + 2.0));
  p.translation_mm = -centre_ct_mm + o.amplitude_mm * Eigen::Vector3d(std::sin(phase + 0.5), std::sin(phase + 1.5),
                                                                      std::sin(phase + 2.5));
  return RigidPose::toTransform(p, centre_ct_mm);
}

/// Renders the sequence. Fails when the CT has no bone or the simulator fails.
inline Result<SimulatedSequence> simulateSequence(const Volume& ct, const SequenceOptions& o) {
  auto bone = BoneSurface::extract(ct);
  if (!bone) return fail(bone.error());
  SimulatedSequence s;
  s.centre_ct_mm = bone.value().centroid_ct_mm();
  StandardViewOptions viewOptions;
  viewOptions.count = o.viewCount;
  viewOptions.cols = viewOptions.rows = o.size_px;
  viewOptions.pixelSpacing_mm = o.pixelSpacing_mm;
  viewOptions.sourceToDetector_mm = o.sourceToDetector_mm;
  viewOptions.sourceToIsocentre_mm = o.sourceToIsocentre_mm;
  auto specs = StandardViews::build(Eigen::Vector3d::Zero(), viewOptions);
  if (!specs) return fail(specs.error());
  std::vector<Camera> cameras;
  for (const ViewSpec& spec : specs.value()) cameras.push_back(spec.camera);
  FluoroscopyOptions physics;
  physics.photonsPerPixel = o.photonsPerPixel;
  for (int f = 0; f < o.frames; ++f) {
    s.T_truth.push_back(sequencePose(s.centre_ct_mm, o, f));
    auto images = FluoroscopySimulator::renderViews(ct, cameras, s.T_truth.back(), physics,
                                                    o.seed + static_cast<std::uint32_t>(f * o.viewCount));
    if (!images) return fail(images.error());
    std::vector<XrayImage> frame;
    for (FloatImage& image : images.value()) {
      XrayImage xray;
      xray.cols = image.cols;
      xray.rows = image.rows;
      xray.modality = "simulated";
      xray.pixels = std::move(image.pixels);
      frame.push_back(std::move(xray));
    }
    s.frames.push_back(std::move(frame));
  }
  for (std::size_t v = 0; v < specs.value().size(); ++v) {
    s.views.push_back(RegistrationView{specs.value()[v].name, s.frames[0][v], cameras[v], {}});
  }
  return s;
}

}  // namespace fct::test
