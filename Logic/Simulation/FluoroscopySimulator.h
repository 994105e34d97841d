#pragma once
// FluoroscopySimulator: a physical forward model of a fluoroscopic C-arm image, deliberately different from the
// registration's DRR (no DrrVolume, DrrRenderer, Siddon or Transgraph code), so that registration results on its
// images are not an "inverse crime".
//
// Per detector pixel: one ray from the source through the pixel centre, integrated through the patient — by default
// the continuous cubic B-spline interpolant of the CT, optionally continued beyond the CT's end faces
// (CubicBsplinePatient), so no voxel edge of the CT shows; or the CT's own voxel boxes with exact path lengths
// (MaterialPathTracer) — into the mass per area of air, soft tissue, cortical bone and metal (HuMaterialModel); objects that are not in the CT (K-wires, screws, a plate near the bone; calibration-grid
// spheres fixed to the C-arm) add their analytic chord lengths (ForeignObjectSet). Beer–Lambert per bin of a
// polyenergetic tube spectrum (XraySpectrum) with NIST µ/ρ (MassAttenuationTable) gives the transmitted photons;
// an energy-integrating detector weights them by energy. A scatter haze adds scatterToPrimary times the primary
// signal blurred by a Gaussian of scatterSigma_mm on the detector (a broad, low-contrast background). Then, in order: a circular collimator (no photons outside),
// Poisson quantum noise per energy bin at the given dose, a Gaussian point-spread function, image-intensifier
// pincushion / S-distortion (IntensifierDistortion), vignetting, and the display transfer gain · s^gamma + offset.
//
// Signal s: 1 for a ray through air, Σ_b n_b E_b exp(−Σ_m (µ/ρ)_m(E_b) M_m) / Σ_b n_b E_b without noise (n_b the
// bin's photon fraction, M_m the mass per area of material m). Pixel value (MONOCHROME2, bright = more signal):
// offset + gain · (v · s / s_ref)^gamma, v the vignetting, s_ref the exposure reference (see automaticExposure).
// With noise, s / s_ref = Σ_b k_b E_b / (N Σ_b n_b E_b), k_b ~ Poisson(N n_b T_b / s_ref), N = photonsPerPixel.

#include <Eigen/Geometry>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "Base/Result.h"
#include "Geometry/Camera.h"
#include "Image/FloatImage.h"
#include "Image/Volume.h"
#include "IO/Project/ViewFile.h"
#include "Simulation/Physics/HuMaterialModel.h"
#include "Simulation/SimulatedCaseWriter.h"

namespace fct {

/// How the simulator turns the CT into a patient.
enum class PatientModel {
  CubicBspline,  ///< the continuous cubic B-spline interpolant of the CT (CubicBsplinePatient)
  VoxelBoxes,    ///< the CT's voxel boxes with exact path lengths (MaterialPathTracer): carries the CT's staircase
};

/// Every parameter of the physical simulation. Defaults: an ideal noiseless detector at 80 kVp, no
/// intensifier effects, no foreign objects; each effect is switched on by its parameter.
struct FluoroscopyOptions {
  // Beam and materials.
  double tubeVoltage_kvp = 80.0;      ///< tube peak voltage, 50..120 kVp
  double filtration_mmAl = 2.5;       ///< total tube filtration in mm Al
  double spectrumBinWidth_keV = 5.0;  ///< energy bin width, 1..20 keV
  double monochromatic_keV = 0.0;     ///< > 0: a monochromatic beam at this energy (10..150 keV) instead of the spectrum
  HuMaterialModel materials;          ///< HU -> material densities
  PatientModel patient = PatientModel::CubicBspline;  ///< the patient the rays cross
  double patientExtension_mm = 0.0;   ///< CubicBspline: the patient continues this far beyond the CT's end faces, 0..1000
  // Exposure, dose and detector.
  /// Automatic exposure (a C-arm's brightness control): the tube output is scaled per view so that the reference
  /// level — the 99th percentile of the noiseless signal over the exposed pixels — receives photonsPerPixel photons
  /// and the pixel value `gain`. Off: the reference is an unattenuated ray (s = 1), as for the Beer–Lambert tests.
  bool automaticExposure = true;
  double photonsPerPixel = 0.0;       ///< photons per pixel at the reference level (all bins); 0 = noiseless
  double psfSigma_px = 0.0;           ///< Gaussian point-spread function sigma in pixels; 0 = none
  double scatterToPrimary = 0.0;      ///< scatter haze: this fraction of the blurred primary signal is added, 0..5
  double scatterSigma_mm = 40.0;      ///< scatter haze: Gaussian sigma on the detector in mm, 1..500
  double gain = 50000.0;              ///< pixel value of the reference level, before offset
  double offset = 0.0;                ///< added to every pixel (dark level)
  double gamma = 1.0;                 ///< display gamma applied to the signal, > 0
  // Image intensifier and collimator.
  double pincushion = 0.0;            ///< radial distortion k: r_observed = r (1 + k (r/R)^2), R = half the smaller detector side; |k| <= 0.1
  double sDistortion_deg = 0.0;       ///< S-distortion: rotation by sDistortion_deg · (r/R)^2 about the centre; |.| <= 10
  double vignetting = 0.0;            ///< brightness loss at the detector corners: v = 1 − vignetting · (r / half diagonal)^2; 0..0.9
  double collimatorRadiusFraction = 0.0;  ///< > 0: circular collimator of radius fraction · (half the smaller side); 0 = none
  // Objects that are not in the CT.
  int kwireCount = 0;                 ///< K-wires (stainless steel, Ø 2 mm, 150 mm) through the bone surface
  int screwCount = 0;                 ///< bone screws (titanium, Ø 4.5 mm × 40 mm shaft, Ø 8 mm head) into the bone
  bool plate = false;                 ///< a bone plate (stainless steel, 100 × 12 × 3.5 mm) on the bone surface
  int gasPocketCount = 0;             ///< soft-tissue change: bowel-gas pockets (r 8-20 mm) in soft tissue near the bone
  bool calibrationSpheres = false;    ///< a grid of steel spheres fixed to the C-arm near the detector
  double sphereSpacing_mm = 40.0;     ///< grid pitch of the spheres
  double sphereRadius_mm = 1.5;       ///< sphere radius
  double sphereDistanceFromDetector_mm = 150.0;  ///< distance of the sphere grid plane from the detector
  // A dewarp calibration plate: steel beads on a square grid in a plane parallel to the detector.
  double gridPitch_mm = 0.0;          ///< > 0: writeCase also writes a grid plate image per view (see writeCase); 0..100
  double gridBeadRadius_mm = 1.5;     ///< bead radius, below half the pitch
  double gridDistanceFromDetector_mm = 20.0;  ///< distance of the plate from the detector
  double boneThreshold_hu = 300.0;    ///< voxels at or above are bone when placing objects
  std::uint32_t seed = 1;             ///< object placement; writeCase uses seed + n as view n's noise seed
};

/// Simulates fluoroscopic X-ray images with a physical model.
class FluoroscopySimulator {
 public:
  /// Detector image (MONOCHROME2 sense: bright = more signal) of `ct` (HU) at T_world_from_ct (CT LPS mm -> world
  /// LPS mm) seen by `camera`; `viewSeed` drives this view's quantum noise (rows use independent streams, so the
  /// result does not depend on the thread count). Fails on bad options, a pose that is not a rigid transform, an
  /// empty or non-finite CT, or no bone to place requested objects on.
  static Result<FloatImage> render(const Volume& ct, const Camera& camera, const Eigen::Isometry3d& T_world_from_ct,
                                   const FluoroscopyOptions& options, std::uint32_t viewSeed);

  /// render() of each camera (view n with noise seed firstViewSeed + n; the same objects in every view), preparing the
  /// patient once. Fails as render() does.
  static Result<std::vector<FloatImage>> renderViews(const Volume& ct, const std::vector<Camera>& cameras,
                                                     const Eigen::Isometry3d& T_world_from_ct,
                                                     const FluoroscopyOptions& options, std::uint32_t firstViewSeed);

  /// Receives frame `frame`'s images (one per camera); an error stops renderSequence with it.
  using SequenceFrameSink = std::function<Status(int frame, std::vector<FloatImage> images)>;

  /// A sequence: render() of every camera at each pose (frame k, view n with noise seed firstSeed + k * cameras + n),
  /// preparing the patient and the objects (placed by options.seed) once, and passing each frame to `onFrame` as soon
  /// as it is rendered. The objects move with the bone, or with `implantsFixedInWorld` stay where they are at the
  /// first pose (tools held still while the bone moves). Fails as render() does (naming frame and view), on no
  /// pose, or with the first error of `onFrame`.
  static Status renderSequence(const Volume& ct, const std::vector<Camera>& cameras,
                               const std::vector<Eigen::Isometry3d>& poses_world_from_ct,
                               const FluoroscopyOptions& options, std::uint32_t firstSeed, bool implantsFixedInWorld,
                               const SequenceFrameSink& onFrame);

  /// Image of the dewarp calibration plate alone (no patient, no calibration spheres; beads of
  /// options.gridBeadRadius_mm at options.gridPitch_mm, centred on the principal ray) seen by `camera` through the
  /// same beam, noise (viewSeed), blur, intensifier distortion and detector response as render(). Fails on a
  /// non-positive pitch, bad options or plate settings.
  static Result<FloatImage> renderGridPlate(const Camera& camera, const FluoroscopyOptions& options,
                                            std::uint32_t viewSeed);

  /// Renders every view (view n with noise seed options.seed + n; the same objects in every view) and writes in
  /// `outDir` (created if missing): <view>.png (16-bit), views.json (with the calibration spheres' shadows as
  /// calibration_spheres_px when spheres are on), truth_pose.json, simulation.json (every parameter, the spectrum,
  /// the µ/ρ used, the objects, `ctSource`) and, with distortion, <view>_distortion_dcol.nrrd / _drow.nrrd (per
  /// ideal pixel, observed − ideal position in px; see IntensifierDistortion::dewarp); with gridPitch_mm > 0,
  /// <view>_grid.png, renderGridPlate() of the view (noise seed options.seed + view count + n). All images are computed
  /// before anything is written. Fails as render() does, on an empty view list or unusable view names, or an
  /// unwritable folder.
  static Result<SimulatedCase> writeCase(const Volume& ct, const std::vector<ViewSpec>& views,
                                         const Eigen::Isometry3d& T_world_from_ct, const FluoroscopyOptions& options,
                                         const std::filesystem::path& outDir, const std::string& ctSource);
};

}  // namespace fct
