#include "Evaluation/StudyXraySource.h"

#include <fmt/format.h>

#include <cmath>

#include "Simulation/CtSliceDegrader.h"

namespace fct {

/// The simulated C-arm and patient: the CT's continuous interpolant continued 60 mm beyond its end faces, 80 kVp
/// polyenergetic beam, a scatter haze (scatter-to-primary 0.1, sigma 40 mm: a C-arm with an anti-scatter grid), quantum noise, detector blur and
/// vignetting; with foreign objects, 2 K-wires and 2 screws; no distortion or collimator (studied separately).
FluoroscopyOptions StudyXraySource::forwardModel(bool foreignObjects) {
  FluoroscopyOptions o;
  o.patient = PatientModel::CubicBspline;
  o.patientExtension_mm = 60.0;
  o.tubeVoltage_kvp = 80.0;
  o.scatterToPrimary = 0.1;
  o.scatterSigma_mm = 40.0;
  o.photonsPerPixel = 10000.0;
  o.psfSigma_px = 0.7;
  o.vignetting = 0.1;
  if (foreignObjects) {
    o.kwireCount = 2;
    o.screwCount = 2;
  }
  return o;
}

std::string StudyXraySource::description() {
  const FluoroscopyOptions o = forwardModel(true);
  return fmt::format("FluoroscopySimulator on the original CT as a continuous patient (its cubic B-spline interpolant, "
                     "continued {:g} mm beyond the CT's end faces by mirroring the end slabs; no voxel edges), {:g} kVp "
                     "spectrum with NIST attenuation, scatter haze (scatter-to-primary {:g}, sigma {:g} mm), automatic "
                     "exposure, Poisson noise at {:g} photons per pixel at the reference level, PSF sigma {:g} px, "
                     "vignetting {:g}; realistic and bad scenarios add {} K-wires and {} screws that are not in the CT; "
                     "no distortion or collimator): a forward model independent of registration's grid and DRR",
                     o.patientExtension_mm, o.tubeVoltage_kvp, o.scatterToPrimary, o.scatterSigma_mm,
                     o.photonsPerPixel, o.psfSigma_px, o.vignetting, o.kwireCount, o.screwCount);
}

namespace {

/// A simulated detector image as the X-ray registration reads.
XrayImage toXray(FloatImage image) {
  XrayImage xray;
  xray.cols = image.cols;
  xray.rows = image.rows;
  xray.modality = "simulated";
  xray.pixels = std::move(image.pixels);
  return xray;
}

}  // namespace

Result<std::vector<RegistrationView>> StudyXraySource::simulate(const Volume& ct, const std::vector<ViewSpec>& views,
                                                                const Eigen::Isometry3d& T_world_from_ct,
                                                                std::uint32_t seed, bool foreignObjects) {
  FluoroscopyOptions options = forwardModel(foreignObjects);
  options.seed = seed;
  std::vector<RegistrationView> out;
  for (std::size_t v = 0; v < views.size(); ++v) {
    const ViewSpec& spec = views[v];
    auto image = FluoroscopySimulator::render(ct, spec.camera, T_world_from_ct, options,
                                              seed + static_cast<std::uint32_t>(v));
    if (!image) return fail(fmt::format("view '{}': {}", spec.name, image.error()));
    out.push_back(RegistrationView{spec.name, toXray(std::move(image).value()), spec.camera, {}});
  }
  return out;
}

Status StudyXraySource::simulateSequence(const Volume& ct, const std::vector<ViewSpec>& views,
                                         const std::vector<Eigen::Isometry3d>& poses_world_from_ct, std::uint32_t seed,
                                         bool foreignObjects, const FrameSink& onFrame) {
  FluoroscopyOptions options = forwardModel(foreignObjects);
  options.seed = seed;
  std::vector<Camera> cameras;
  for (const ViewSpec& spec : views) cameras.push_back(spec.camera);
  return FluoroscopySimulator::renderSequence(
      ct, cameras, poses_world_from_ct, options, seed, foreignObjects,
      [&](int frame, std::vector<FloatImage> images) -> Status {
        std::vector<XrayImage> xrays;
        for (FloatImage& image : images) xrays.push_back(toXray(std::move(image)));
        return onFrame(frame, std::move(xrays));
      });
}

Result<Volume> StudyXraySource::registrationCt(const Volume& ct, double sliceSpacing_mm) {
  if (!std::isfinite(sliceSpacing_mm) || sliceSpacing_mm < 0.0) {
    return fail(fmt::format("slice spacing must be 0 (the original CT) or positive, got {} mm", sliceSpacing_mm));
  }
  if (effectiveSliceSpacing_mm(ct, sliceSpacing_mm) == 0.0) return ct;
  return CtSliceDegrader::degrade(ct, sliceSpacing_mm);
}

double StudyXraySource::effectiveSliceSpacing_mm(const Volume& ct, double sliceSpacing_mm) {
  return sliceSpacing_mm > ct.spacing_mm().z() ? sliceSpacing_mm : 0.0;
}

}  // namespace fct
