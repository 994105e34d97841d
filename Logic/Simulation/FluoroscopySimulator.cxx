#include "Simulation/FluoroscopySimulator.h"

#include <fmt/core.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>

#include "Base/SeededRandom.h"
#include "Simulation/ForeignObjectSet.h"
#include "Simulation/IntensifierDistortion.h"
#include "Simulation/Physics/CubicBsplinePatient.h"
#include "Simulation/Physics/MaterialPathTracer.h"
#include "Simulation/Physics/XraySpectrum.h"

namespace fct {

namespace {

/// What every view of a case shares: the spectrum with its attenuation table, the patient (one of the two models)
/// and the implants.
struct Scene {
  XraySpectrum spectrum;
  std::vector<MassPaths> massAttenuation_cm2_per_g;  ///< per bin, per material
  std::optional<CubicBsplinePatient> continuousPatient;  ///< the patient model in use; neither for a scene without
  std::optional<MaterialPathTracer> voxelPatient;         ///< patient (a grid plate image)
  ForeignObjectSet implants;  ///< CT frame

  /// The patient's mass paths along a ray (CT frame); zero without a patient.
  MassPaths trace(const Eigen::Vector3d& origin_ct_mm, const Eigen::Vector3d& direction_ct) const {
    if (continuousPatient) return continuousPatient->trace(origin_ct_mm, direction_ct);
    if (voxelPatient) return voxelPatient->trace(origin_ct_mm, direction_ct);
    return MassPaths{};
  }
};

/// What a view shows: the patient with its implants and the calibration spheres the options ask for, or only the
/// dewarp calibration plate (the patient out of the beam, as when the intensifier is calibrated).
enum class ViewContent { Patient, GridPlate };

/// One rendered view.
struct RenderedView {
  FloatImage image;
  std::vector<PixelCircle> spheres;   ///< shadows of the calibration spheres (observed pixels)
  std::optional<DisplacementField> field;   ///< when distorted
  double maxLineIntegral = 0.0;             ///< -ln of the smallest noiseless signal inside the collimator
  double referenceSignal = 1.0;             ///< noiseless signal mapped to `gain` (1 = an unattenuated ray)
};

/// The spectrum settings inside the simulator's options.
SpectrumOptions spectrumOptions(const FluoroscopyOptions& o) {
  return {o.tubeVoltage_kvp, o.filtration_mmAl, o.spectrumBinWidth_keV, o.monochromatic_keV};
}

/// Checks the detector and placement settings (the spectrum, HU model, distortion and objects check their own).
Status validate(const FluoroscopyOptions& o) {
  const auto bad = [](double v, double low, double high) { return !(v >= low && v <= high); };
  if (bad(o.photonsPerPixel, 0.0, 1e9)) {
    return fail(fmt::format("dose must be 0 (noiseless) or a positive photon count per pixel up to 1e9, got {}",
                            o.photonsPerPixel));
  }
  if (bad(o.psfSigma_px, 0.0, 20.0)) return fail(fmt::format("PSF sigma must be 0..20 px, got {}", o.psfSigma_px));
  if (bad(o.scatterToPrimary, 0.0, 5.0)) {
    return fail(fmt::format("scatter-to-primary ratio must be 0..5, got {}", o.scatterToPrimary));
  }
  if (bad(o.scatterSigma_mm, 1.0, 500.0)) {
    return fail(fmt::format("scatter haze sigma must be 1..500 mm, got {}", o.scatterSigma_mm));
  }
  if (o.patient == PatientModel::VoxelBoxes && o.patientExtension_mm != 0.0) {
    return fail("a patient extension beyond the CT needs the continuous (cubic B-spline) patient model");
  }
  if (!(o.gain > 0.0 && std::isfinite(o.gain))) return fail(fmt::format("gain must be positive, got {}", o.gain));
  if (!std::isfinite(o.offset)) return fail(fmt::format("offset must be finite, got {}", o.offset));
  if (bad(o.gamma, 0.1, 10.0)) return fail(fmt::format("gamma must be 0.1..10, got {}", o.gamma));
  if (bad(o.vignetting, 0.0, 0.9)) return fail(fmt::format("vignetting must be 0..0.9, got {}", o.vignetting));
  if (bad(o.collimatorRadiusFraction, 0.0, 1.5)) {
    return fail(fmt::format("collimator radius fraction must be 0 (none) or up to 1.5, got {}", o.collimatorRadiusFraction));
  }
  if (bad(o.gridPitch_mm, 0.0, 100.0)) {
    return fail(fmt::format("grid plate pitch must be 0 (none) up to 100 mm, got {}", o.gridPitch_mm));
  }
  if (bad(o.boneThreshold_hu, -500.0, 3000.0)) {
    return fail(fmt::format("bone threshold must be -500..3000 HU, got {}", o.boneThreshold_hu));
  }
  return Ok{};
}

/// Fails unless T's linear part is a proper rotation.
Status checkRigid(const Eigen::Isometry3d& T) {
  const Eigen::Matrix3d R = T.linear();
  if (!T.matrix().allFinite() || (R.transpose() * R - Eigen::Matrix3d::Identity()).norm() > 1e-6 || R.determinant() < 0.0) {
    return fail("pose T_world_from_ct is not a rigid transform (its 3x3 part must be a rotation: orthonormal, det +1)");
  }
  return Ok{};
}

/// Builds the spectrum, attenuation table, patient model and implants shared by every view (neither without
/// a CT).
Result<Scene> prepareScene(const Volume* ct, const FluoroscopyOptions& options) {
  if (Status valid = validate(options); !valid) return fail(valid.error());
  auto spectrum = XraySpectrum::create(spectrumOptions(options));
  if (!spectrum.ok()) return fail(spectrum.error());
  Scene scene{std::move(spectrum).value(), {}, std::nullopt, std::nullopt, ForeignObjectSet()};
  if (ct) {
    auto implants = ForeignObjectSet::placeNearBone(
        *ct, {options.kwireCount, options.screwCount, options.plate, options.gasPocketCount, options.boneThreshold_hu,
              options.seed});
    if (!implants.ok()) return fail(implants.error());
    scene.implants = std::move(implants).value();
    if (options.patient == PatientModel::CubicBspline) {
      auto patient = CubicBsplinePatient::create(*ct, options.materials, options.patientExtension_mm);
      if (!patient.ok()) return fail(patient.error());
      scene.continuousPatient = std::move(patient).value();
    } else {
      auto tracer = MaterialPathTracer::create(*ct, options.materials);
      if (!tracer.ok()) return fail(tracer.error());
      scene.voxelPatient = std::move(tracer).value();
    }
  }
  for (const SpectrumBin& bin : scene.spectrum.bins()) {
    MassPaths mu{};
    for (int m = 0; m < kMaterialCount; ++m) {
      auto value = MassAttenuationTable::massAttenuation_cm2_per_g(static_cast<Material>(m), bin.energy_keV);
      if (!value.ok()) return fail(value.error());
      mu[m] = value.value();
    }
    scene.massAttenuation_cm2_per_g.push_back(mu);
  }
  return scene;
}

/// Where one view's rays go: the source and camera rotation in the CT frame, the intrinsics, and the detector centre
/// and collimator radius in pixels (0: no collimator).
struct ViewGeometry {
  CameraIntrinsics in;
  Eigen::Matrix3d K;
  Eigen::Vector3d source_ct;
  Eigen::Matrix3d R_ct_from_camera;
  Eigen::Vector2d centre_px;
  double collimator_px = 0.0;
  Eigen::Vector3d source_implants;         ///< the source in the implants' frame (the CT frame where they were
  Eigen::Matrix3d R_implants_from_camera;  ///< placed, at their own world pose)
};

/// The ray geometry of `camera` with the CT at T_world_from_ct and the implants at T_world_from_implants.
ViewGeometry viewGeometry(const Camera& camera, const Eigen::Isometry3d& T_world_from_ct,
                          const Eigen::Isometry3d& T_world_from_implants, const FluoroscopyOptions& options) {
  const CameraIntrinsics& in = camera.intrinsics();
  const Eigen::Isometry3d T_ct_from_camera = T_world_from_ct.inverse() * camera.T_world_from_camera();
  const Eigen::Isometry3d T_implants_from_camera = T_world_from_implants.inverse() * camera.T_world_from_camera();
  return {in,
          camera.K(),
          T_ct_from_camera.translation(),
          T_ct_from_camera.linear(),
          Eigen::Vector2d(0.5 * (in.cols - 1), 0.5 * (in.rows - 1)),
          options.collimatorRadiusFraction * 0.5 * std::min(in.cols, in.rows),
          T_implants_from_camera.translation(),
          T_implants_from_camera.linear()};
}

/// The spectrum bins' photon fractions and energy weights (photon fraction × keV) with the weights' sum.
struct SpectrumWeights {
  std::vector<double> photonFraction;
  std::vector<double> energyWeight;
  double energyNorm = 0.0;
};

/// The weights of the scene's spectrum.
SpectrumWeights spectrumWeights(const XraySpectrum& spectrum) {
  const std::size_t binCount = spectrum.bins().size();
  SpectrumWeights w{std::vector<double>(binCount), std::vector<double>(binCount), 0.0};
  for (std::size_t b = 0; b < binCount; ++b) {
    w.photonFraction[b] = spectrum.bins()[b].photonFraction;
    w.energyWeight[b] = w.photonFraction[b] * spectrum.bins()[b].energy_keV;
    w.energyNorm += w.energyWeight[b];
  }
  return w;
}

/// The noiseless energy-integrating signal of a ray with these mass paths (1 = unattenuated); also fills each bin's
/// transmission.
double noiselessSignal(const Scene& scene, const SpectrumWeights& w, const MassPaths& paths,
                       std::vector<double>& transmission) {
  double signal = 0.0;
  for (std::size_t b = 0; b < transmission.size(); ++b) {
    double attenuation = 0.0;
    for (int m = 0; m < kMaterialCount; ++m) attenuation += scene.massAttenuation_cm2_per_g[b][m] * paths[m];
    transmission[b] = std::exp(-attenuation);
    signal += w.energyWeight[b] * transmission[b];
  }
  return signal / w.energyNorm;
}

/// The intensifier distortion the options ask for; none when pincushion and S-distortion are 0.
Result<std::optional<IntensifierDistortion>> distortionFor(const CameraIntrinsics& in,
                                                           const FluoroscopyOptions& options) {
  if (options.pincushion == 0.0 && options.sDistortion_deg == 0.0) return std::optional<IntensifierDistortion>();
  auto created = IntensifierDistortion::create(in.cols, in.rows, options.pincushion, options.sDistortion_deg);
  if (!created.ok()) return fail(created.error());
  return std::optional<IntensifierDistortion>(std::move(created).value());
}

/// The objects fixed to the C-arm of `camera` (camera frame): for the patient, the calibration-grid spheres (an
/// empty set when the options have none); for a grid plate image, the plate's beads.
Result<ForeignObjectSet> detectorObjectsFor(const Camera& camera, const FluoroscopyOptions& options,
                                            ViewContent content) {
  if (content == ViewContent::GridPlate) {
    return ForeignObjectSet::calibrationGrid(camera, options.gridPitch_mm, options.gridBeadRadius_mm,
                                             options.gridDistanceFromDetector_mm);
  }
  if (!options.calibrationSpheres) return ForeignObjectSet();
  return ForeignObjectSet::calibrationGrid(camera, options.sphereSpacing_mm, options.sphereRadius_mm,
                                           options.sphereDistanceFromDetector_mm);
}

/// Per pixel (row-major): the mass paths of its ray, whether the collimator lets it through, and its noiseless
/// scatter signal (empty without a scatter haze).
struct LineIntegrals {
  std::vector<MassPaths> pixelPaths;
  std::vector<std::uint8_t> exposed;
  std::vector<float> scatter;
};

/// Pass 1: material path integrals through the patient and the implants (when the view shows the patient and the
/// scene has one) and the detector-fixed spheres for every pixel inside the collimator, with their noiseless signal
/// written to `image` (pixels outside stay 0).
LineIntegrals traceLineIntegrals(const Scene& scene, const ViewGeometry& g, const ForeignObjectSet& spheres,
                                 const SpectrumWeights& weights, ViewContent content, FloatImage& image) {
  const bool patient = content == ViewContent::Patient;
  const std::size_t pixelCount = static_cast<std::size_t>(g.in.cols) * g.in.rows;
  LineIntegrals rays{std::vector<MassPaths>(pixelCount), std::vector<std::uint8_t>(pixelCount, 0), {}};
  tbb::parallel_for(0, g.in.rows, [&](int row) {
    std::vector<double> transmission(weights.energyWeight.size());
    for (int col = 0; col < g.in.cols; ++col) {
      const std::size_t index = static_cast<std::size_t>(row) * g.in.cols + col;
      if (g.collimator_px > 0.0 && (Eigen::Vector2d(col, row) - g.centre_px).norm() > g.collimator_px) continue;
      const Eigen::Vector3d direction_camera =
          Eigen::Vector3d((col - g.K(0, 2)) / g.K(0, 0), (row - g.K(1, 2)) / g.K(1, 1), 1.0).normalized();
      const Eigen::Vector3d direction_ct = g.R_ct_from_camera * direction_camera;
      MassPaths& paths = rays.pixelPaths[index];
      if (patient) {
        paths = scene.trace(g.source_ct, direction_ct);
        scene.implants.accumulate(g.source_implants, g.R_implants_from_camera * direction_camera, paths);
      }
      spheres.accumulate(Eigen::Vector3d::Zero(), direction_camera, paths);
      for (double& path : paths) path = std::max(0.0, path);  // a gas pocket removes at most the tissue there
      image.pixels[index] = static_cast<float>(noiselessSignal(scene, weights, paths, transmission));
      rays.exposed[index] = 1;
    }
  });
  return rays;
}

/// The scatter haze: scatterToPrimary times the noiseless primary signal of `image` blurred by a Gaussian of
/// scatterSigma_mm on the detector (pixels outside the collimator add nothing and get nothing), kept in
/// rays.scatter and added to `image`. Nothing without a haze; fails on an OpenCV error.
Status addScatterHaze(const FluoroscopyOptions& options, const CameraIntrinsics& in, LineIntegrals& rays,
                      FloatImage& image) {
  if (options.scatterToPrimary <= 0.0) return Ok{};
  const double sigma_px = options.scatterSigma_mm / in.pixelSpacing_mm.mean();
  try {
    cv::Mat primary(image.rows, image.cols, CV_32F, image.pixels.data());
    cv::Mat haze;
    cv::GaussianBlur(primary, haze, cv::Size(0, 0), sigma_px, sigma_px, cv::BORDER_REFLECT);
    rays.scatter.assign(image.pixels.size(), 0.0f);
    for (std::size_t index = 0; index < image.pixels.size(); ++index) {
      if (!rays.exposed[index]) continue;
      rays.scatter[index] = static_cast<float>(options.scatterToPrimary * haze.at<float>(static_cast<int>(index)));
      image.pixels[index] += rays.scatter[index];
    }
  } catch (const cv::Exception& e) {
    return fail(fmt::format("scatter haze failed: {}", e.what()));
  }
  return Ok{};
}

/// Sets the view's maxLineIntegral and referenceSignal (automatic exposure: the 99th percentile of the exposed
/// noiseless signals; else 1) from its noiseless image. Fails when no pixel is exposed or no X-ray gets through.
Status measureExposure(const std::vector<std::uint8_t>& exposed, const FluoroscopyOptions& options,
                       RenderedView& view) {
  std::vector<float> field;
  for (std::size_t index = 0; index < exposed.size(); ++index) {
    if (exposed[index]) field.push_back(view.image.pixels[index]);
  }
  if (field.empty()) return fail("the collimator leaves no pixel exposed; raise the collimator radius");
  view.maxLineIntegral = -std::log(std::max(1e-30, double(*std::min_element(field.begin(), field.end()))));
  view.referenceSignal = 1.0;
  if (options.automaticExposure) {
    const auto reference = field.begin() + static_cast<std::ptrdiff_t>(0.99 * double(field.size() - 1));
    std::nth_element(field.begin(), reference, field.end());
    if (!(*reference > 1e-30f)) return fail("no X-ray reaches the detector through this CT; check the pose and views");
    view.referenceSignal = *reference;
  }
  return Ok{};
}

/// Pass 2: exposure scaling of every exposed pixel by the reference signal and, with a dose, Poisson quantum noise per
/// energy bin, and for the scatter haze at the spectrum's mean energy (one random stream per row, from viewSeed).
void exposeWithQuantumNoise(const Scene& scene, const SpectrumWeights& weights, const LineIntegrals& rays,
                            const FluoroscopyOptions& options, std::uint32_t viewSeed, double referenceSignal,
                            FloatImage& image) {
  const double photons = options.photonsPerPixel / referenceSignal;
  tbb::parallel_for(0, image.rows, [&](int row) {
    SeededRandom random(SeededRandom::streamSeed(viewSeed, static_cast<std::uint32_t>(row)));
    std::vector<double> transmission(weights.energyWeight.size());
    for (int col = 0; col < image.cols; ++col) {
      const std::size_t index = static_cast<std::size_t>(row) * image.cols + col;
      if (!rays.exposed[index]) continue;
      float& out = image.pixels[index];
      if (options.photonsPerPixel == 0.0) {
        out = static_cast<float>(out / referenceSignal);
        continue;
      }
      noiselessSignal(scene, weights, rays.pixelPaths[index], transmission);
      double energy = 0.0;
      for (std::size_t b = 0; b < transmission.size(); ++b) {
        energy += static_cast<double>(random.poisson(photons * weights.photonFraction[b] * transmission[b])) *
                  scene.spectrum.bins()[b].energy_keV;
      }
      if (!rays.scatter.empty()) {
        energy += static_cast<double>(random.poisson(photons * rays.scatter[index])) * weights.energyNorm;
      }
      out = static_cast<float>(energy / (options.photonsPerPixel * weights.energyNorm));
    }
  });
}

/// The detector's point-spread function: a Gaussian blur of sigma_px (0: none), in place. Fails on an OpenCV error.
Status blurPointSpread(double sigma_px, FloatImage& image) {
  if (sigma_px <= 0.0) return Ok{};
  try {
    cv::Mat mat(image.rows, image.cols, CV_32F, image.pixels.data());
    cv::GaussianBlur(mat, mat, cv::Size(0, 0), sigma_px, sigma_px, cv::BORDER_REPLICATE);
  } catch (const cv::Exception& e) {
    return fail(fmt::format("point-spread blur failed: {}", e.what()));
  }
  return Ok{};
}

/// Warps the view's image by the intensifier distortion and keeps its displacement field.
Status distortView(const IntensifierDistortion& distortion, RenderedView& view) {
  auto warped = distortion.warp(view.image);
  if (!warped.ok()) return fail(warped.error());
  view.image = std::move(warped).value();
  view.field = distortion.field();
  return Ok{};
}

/// The detector's grey values: offset + gain × (vignetting × signal)^gamma, vignetting falling off with the squared
/// distance from centre_px, in place.
void applyDetectorResponse(const FluoroscopyOptions& options, const Eigen::Vector2d& centre_px, FloatImage& image) {
  const double halfDiagonal2 = centre_px.squaredNorm();
  tbb::parallel_for(0, image.rows, [&](int row) {
    for (int col = 0; col < image.cols; ++col) {
      const double vignette =
          1.0 - options.vignetting * (Eigen::Vector2d(col, row) - centre_px).squaredNorm() / halfDiagonal2;
      float& value = image.at(col, row);
      value = static_cast<float>(options.offset +
                                 options.gain * std::pow(std::max(0.0, vignette * double(value)), options.gamma));
    }
  });
}

/// The observed shadow (centre and radius in pixels, after the distortion if any) of each calibration sphere.
std::vector<PixelCircle> sphereShadows(const ForeignObjectSet& spheres, const ViewGeometry& g,
                                       const std::optional<IntensifierDistortion>& distortion) {
  std::vector<PixelCircle> shadows;
  for (const ForeignObject& sphere : spheres.objects()) {
    const Eigen::Vector3d uvw = g.K * sphere.a_mm;
    Eigen::Vector2d centre = uvw.head<2>() / uvw.z();
    const double radius_px =
        sphere.radius_mm * g.in.sourceToDetector_mm / sphere.a_mm.z() / g.in.pixelSpacing_mm.minCoeff();
    double radius = radius_px;
    if (distortion) {
      const Eigen::Vector2d observed = distortion->distort(centre);
      radius = std::max((distortion->distort(centre + Eigen::Vector2d(radius_px, 0)) - observed).norm(),
                        (distortion->distort(centre + Eigen::Vector2d(0, radius_px)) - observed).norm());
      centre = observed;
    }
    shadows.push_back({centre, radius});
  }
  return shadows;
}

/// Renders one view of a prepared scene; the pose must already be checked rigid. The implants move with the bone,
/// or stay at T_world_from_implants when one is given. Fails on an empty detector, bad distortion, sphere or plate
/// settings, a collimator or pose that lets no X-ray through, or an image-processing error.
Result<RenderedView> renderView(const Scene& scene, const Camera& camera, const Eigen::Isometry3d& T_world_from_ct,
                                const FluoroscopyOptions& options, std::uint32_t viewSeed,
                                ViewContent content = ViewContent::Patient,
                                const Eigen::Isometry3d* T_world_from_implants = nullptr) {
  const ViewGeometry geometry =
      viewGeometry(camera, T_world_from_ct, T_world_from_implants ? *T_world_from_implants : T_world_from_ct, options);
  if (geometry.in.cols <= 0 || geometry.in.rows <= 0) return fail("camera has an empty detector; check the view file");
  auto distortion = distortionFor(geometry.in, options);
  if (!distortion.ok()) return fail(distortion.error());
  auto spheres = detectorObjectsFor(camera, options, content);
  if (!spheres.ok()) return fail(spheres.error());
  const SpectrumWeights weights = spectrumWeights(scene.spectrum);

  RenderedView view;
  view.image = FloatImage::filled(geometry.in.cols, geometry.in.rows);
  LineIntegrals rays = traceLineIntegrals(scene, geometry, spheres.value(), weights, content, view.image);
  if (Status haze = addScatterHaze(options, geometry.in, rays, view.image); !haze) return fail(haze.error());
  if (Status exposure = measureExposure(rays.exposed, options, view); !exposure) return fail(exposure.error());
  exposeWithQuantumNoise(scene, weights, rays, options, viewSeed, view.referenceSignal, view.image);
  if (Status blurred = blurPointSpread(options.psfSigma_px, view.image); !blurred) return fail(blurred.error());
  if (distortion.value()) {
    if (Status distorted = distortView(*distortion.value(), view); !distorted) return fail(distorted.error());
  }
  applyDetectorResponse(options, geometry.centre_px, view.image);
  view.spheres = sphereShadows(spheres.value(), geometry, distortion.value());
  return view;
}

/// Every option, for simulation.json.
nlohmann::ordered_json optionsJson(const FluoroscopyOptions& o) {
  nlohmann::ordered_json j;
  j["tube_voltage_kvp"] = o.tubeVoltage_kvp;
  j["filtration_mm_al"] = o.filtration_mmAl;
  j["spectrum_bin_width_kev"] = o.spectrumBinWidth_keV;
  j["monochromatic_kev"] = o.monochromatic_keV;
  j["hu_air_below"] = o.materials.airBelow_hu;
  j["hu_bone_from"] = o.materials.boneFrom_hu;
  j["hu_cortical_bone"] = o.materials.corticalBone_hu;
  j["hu_metal_from"] = o.materials.metalFrom_hu;
  j["patient_model"] = o.patient == PatientModel::CubicBspline ? "cubic_bspline" : "voxel_boxes";
  j["patient_extension_mm"] = o.patientExtension_mm;
  j["automatic_exposure"] = o.automaticExposure;
  j["photons_per_pixel"] = o.photonsPerPixel;
  j["psf_sigma_px"] = o.psfSigma_px;
  j["scatter_to_primary"] = o.scatterToPrimary;
  j["scatter_sigma_mm"] = o.scatterSigma_mm;
  j["gain"] = o.gain;
  j["offset"] = o.offset;
  j["gamma"] = o.gamma;
  j["pincushion"] = o.pincushion;
  j["s_distortion_deg"] = o.sDistortion_deg;
  j["vignetting"] = o.vignetting;
  j["collimator_radius_fraction"] = o.collimatorRadiusFraction;
  j["kwires"] = o.kwireCount;
  j["screws"] = o.screwCount;
  j["plate"] = o.plate;
  j["gas_pockets"] = o.gasPocketCount;
  j["calibration_spheres"] = o.calibrationSpheres;
  j["sphere_spacing_mm"] = o.sphereSpacing_mm;
  j["sphere_radius_mm"] = o.sphereRadius_mm;
  j["sphere_distance_from_detector_mm"] = o.sphereDistanceFromDetector_mm;
  j["grid_pitch_mm"] = o.gridPitch_mm;
  j["grid_bead_radius_mm"] = o.gridBeadRadius_mm;
  j["grid_distance_from_detector_mm"] = o.gridDistanceFromDetector_mm;
  j["bone_threshold_hu"] = o.boneThreshold_hu;
  j["seed"] = o.seed;
  return j;
}

}  // namespace

Result<FloatImage> FluoroscopySimulator::render(const Volume& ct, const Camera& camera,
                                                const Eigen::Isometry3d& T_world_from_ct,
                                                const FluoroscopyOptions& options, std::uint32_t viewSeed) {
  if (Status rigid = checkRigid(T_world_from_ct); !rigid) return fail(rigid.error());
  auto scene = prepareScene(&ct, options);
  if (!scene.ok()) return fail(scene.error());
  auto view = renderView(scene.value(), camera, T_world_from_ct, options, viewSeed);
  if (!view.ok()) return fail(view.error());
  return std::move(view.value().image);
}

Result<std::vector<FloatImage>> FluoroscopySimulator::renderViews(const Volume& ct, const std::vector<Camera>& cameras,
                                                                 const Eigen::Isometry3d& T_world_from_ct,
                                                                 const FluoroscopyOptions& options,
                                                                 std::uint32_t firstViewSeed) {
  if (Status rigid = checkRigid(T_world_from_ct); !rigid) return fail(rigid.error());
  auto scene = prepareScene(&ct, options);
  if (!scene.ok()) return fail(scene.error());
  std::vector<FloatImage> images;
  for (std::size_t n = 0; n < cameras.size(); ++n) {
    auto view = renderView(scene.value(), cameras[n], T_world_from_ct, options,
                           firstViewSeed + static_cast<std::uint32_t>(n));
    if (!view.ok()) return fail(fmt::format("view {}: {}", n, view.error()));
    images.push_back(std::move(view.value().image));
  }
  return images;
}

Status FluoroscopySimulator::renderSequence(const Volume& ct, const std::vector<Camera>& cameras,
                                            const std::vector<Eigen::Isometry3d>& poses_world_from_ct,
                                            const FluoroscopyOptions& options, std::uint32_t firstSeed,
                                            bool implantsFixedInWorld, const SequenceFrameSink& onFrame) {
  if (poses_world_from_ct.empty()) return fail("a sequence needs at least one pose");
  for (std::size_t k = 0; k < poses_world_from_ct.size(); ++k) {
    if (Status rigid = checkRigid(poses_world_from_ct[k]); !rigid) return fail(fmt::format("frame {}: {}", k, rigid.error()));
  }
  auto scene = prepareScene(&ct, options);
  if (!scene.ok()) return fail(scene.error());
  const Eigen::Isometry3d T_world_from_implants = poses_world_from_ct.front();
  const std::uint32_t viewCount = static_cast<std::uint32_t>(cameras.size());
  for (std::size_t k = 0; k < poses_world_from_ct.size(); ++k) {
    std::vector<FloatImage> images;
    for (std::uint32_t n = 0; n < viewCount; ++n) {
      auto view = renderView(scene.value(), cameras[n], poses_world_from_ct[k], options,
                             firstSeed + static_cast<std::uint32_t>(k) * viewCount + n, ViewContent::Patient,
                             implantsFixedInWorld ? &T_world_from_implants : nullptr);
      if (!view.ok()) return fail(fmt::format("frame {}, view {}: {}", k, n, view.error()));
      images.push_back(std::move(view.value().image));
    }
    if (Status taken = onFrame(static_cast<int>(k), std::move(images)); !taken) return taken;
  }
  return Ok{};
}

Result<FloatImage> FluoroscopySimulator::renderGridPlate(const Camera& camera, const FluoroscopyOptions& options,
                                                         std::uint32_t viewSeed) {
  if (!(options.gridPitch_mm > 0.0)) {
    return fail(fmt::format("a grid plate image needs a positive grid pitch, got {} mm", options.gridPitch_mm));
  }
  auto scene = prepareScene(nullptr, options);
  if (!scene.ok()) return fail(scene.error());
  auto view = renderView(scene.value(), camera, Eigen::Isometry3d::Identity(), options, viewSeed, ViewContent::GridPlate);
  if (!view.ok()) return fail(view.error());
  return std::move(view.value().image);
}

Result<SimulatedCase> FluoroscopySimulator::writeCase(const Volume& ct, const std::vector<ViewSpec>& views,
                                                      const Eigen::Isometry3d& T_world_from_ct,
                                                      const FluoroscopyOptions& options,
                                                      const std::filesystem::path& outDir, const std::string& ctSource) {
  if (Status checked = SimulatedCaseWriter::checkViews(views); !checked) return fail(checked.error());
  if (Status rigid = checkRigid(T_world_from_ct); !rigid) return fail(rigid.error());
  if (outDir.empty()) return fail("output folder is empty");
  auto scene = prepareScene(&ct, options);
  if (!scene.ok()) return fail(scene.error());

  // Compute every image first, so that a failure writes nothing.
  std::vector<ViewSpec> written = views;
  std::vector<FloatImage> images;
  std::vector<SimulatedExtraImage> extras;
  std::vector<double> maxLineIntegral;
  nlohmann::ordered_json perView = nlohmann::ordered_json::array();
  for (std::size_t n = 0; n < views.size(); ++n) {
    const std::uint32_t viewSeed = options.seed + static_cast<std::uint32_t>(n);
    auto view = renderView(scene.value(), views[n].camera, T_world_from_ct, options, viewSeed);
    if (!view.ok()) return fail(fmt::format("view '{}': {}", views[n].name, view.error()));
    nlohmann::ordered_json entry{{"name", views[n].name}, {"image", views[n].name + ".png"}, {"seed", viewSeed},
                                 {"max_line_integral", view.value().maxLineIntegral},
                                 {"exposure_reference_signal", view.value().referenceSignal},
                                 {"calibration_spheres", view.value().spheres.size()}};
    if (view.value().field) {
      const Eigen::Vector2d spacing = views[n].camera.intrinsics().pixelSpacing_mm;
      extras.push_back({views[n].name + "_distortion_dcol.nrrd", view.value().field->dcol_px, spacing});
      extras.push_back({views[n].name + "_distortion_drow.nrrd", view.value().field->drow_px, spacing});
      entry["distortion_field"] = {views[n].name + "_distortion_dcol.nrrd", views[n].name + "_distortion_drow.nrrd"};
    }
    if (options.calibrationSpheres) {
      written[n].calibrationSpheres = view.value().spheres;
    }
    if (options.gridPitch_mm > 0.0) {
      const std::uint32_t gridSeed = options.seed + static_cast<std::uint32_t>(views.size() + n);
      auto grid = renderView(scene.value(), views[n].camera, T_world_from_ct, options, gridSeed, ViewContent::GridPlate);
      if (!grid.ok()) return fail(fmt::format("view '{}': grid plate image: {}", views[n].name, grid.error()));
      const std::string gridFile = views[n].name + "_grid.png";
      extras.push_back({gridFile, std::move(grid.value().image), views[n].camera.intrinsics().pixelSpacing_mm});
      entry["grid_image"] = {{"file", gridFile}, {"seed", gridSeed}, {"beads", grid.value().spheres.size()}};
    }
    perView.push_back(std::move(entry));
    maxLineIntegral.push_back(view.value().maxLineIntegral);
    images.push_back(std::move(view.value().image));
  }

  nlohmann::ordered_json parameters;
  parameters["model"] = "physical";
  parameters["ct"] = ctSource;
  parameters["options"] = optionsJson(options);
  parameters["spectrum"] = scene.value().spectrum.describe();
  nlohmann::ordered_json bins = nlohmann::ordered_json::array();
  for (std::size_t b = 0; b < scene.value().spectrum.bins().size(); ++b) {
    const SpectrumBin& bin = scene.value().spectrum.bins()[b];
    nlohmann::ordered_json mu;
    for (int m = 0; m < kMaterialCount; ++m) {
      mu[std::string(MassAttenuationTable::name(static_cast<Material>(m)))] = scene.value().massAttenuation_cm2_per_g[b][m];
    }
    bins.push_back({{"energy_kev", bin.energy_keV}, {"photon_fraction", bin.photonFraction}, {"mu_over_rho_cm2_per_g", mu}});
  }
  parameters["spectrum_bins"] = bins;
  parameters["attenuation_source"] = "NIST XCOM / NISTIR 5632 (Hubbell & Seltzer), log-log interpolated";
  parameters["implants_ct_lps_mm"] = scene.value().implants.toJson();
  parameters["distortion_model"] =
      "observed = c + Rot(s * rho^2) * (u - c) * (1 + k * rho^2), rho = |u - c| / (min(cols, rows) / 2), c = detector "
      "centre; field files hold observed - ideal per ideal pixel";
  parameters["png"] = "16-bit grey, value = offset + gain * (vignetting * signal / reference)^gamma rounded and clamped to "
                      "0..65535, MONOCHROME2 (bright = more signal)";
  parameters["images"] = perView;
  auto result = SimulatedCaseWriter::write(written, images, extras, T_world_from_ct, parameters, outDir);
  if (!result.ok()) return fail(result.error());
  result.value().maxLineIntegral = std::move(maxLineIntegral);
  return result;
}

}  // namespace fct
