#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <fstream>

#include "IO/Project/ViewFile.h"
#include "Simulation/FluoroscopySimulator.h"
#include "Simulation/PhantomBuilder.h"
#include "Simulation/Physics/MassAttenuationTable.h"
#include "Simulation/StandardViews.h"
#include "TestSupport.h"

namespace {

/// A CT of `thickness_mm` of water-equivalent tissue (0 HU) along k, 80 x 80 mm across, in air, centred at LPS 0.
fct::Volume waterSlab(double thickness_mm) {
  const double spacing = 2.0;
  const int slices = static_cast<int>(std::round(thickness_mm / spacing));
  return fct::Volume::create(Eigen::Vector3i(40, 40, slices), Eigen::Vector3d::Constant(spacing),
                             Eigen::Vector3d(-39.0, -39.0, -(slices - 1) * spacing / 2), Eigen::Matrix3d::Identity(), 0.0f)
      .value();
}

/// A camera looking along LPS +z at the origin (SID 1000 mm, SAD 800 mm), small detector.
fct::Camera axialCamera(int cols = 41, int rows = 31, double pixel_mm = 1.0) {
  return fct::Camera::lookingAt(Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity(), 800.0, 1000.0, cols, rows, pixel_mm);
}

/// Options with absolute exposure: pixel value = transmitted signal s (1 for air).
fct::FluoroscopyOptions absolute() {
  fct::FluoroscopyOptions options;
  options.automaticExposure = false;
  options.gain = 1.0;
  return options;
}

double muWater60(double energy_keV = 60.0) {
  return fct::MassAttenuationTable::massAttenuation_cm2_per_g(fct::Material::SoftTissue, energy_keV).value();
}

fct::Volume smallPhantom() {
  fct::PhantomOptions options;
  options.dims = Eigen::Vector3i(48, 48, 36);
  options.spacing_mm = 3.3;
  return fct::PhantomBuilder::build(options).value();
}

}  // namespace

TEST(FluoroscopySimulator, WaterSlabAttenuatesAsBeerLambertForAMonochromaticBeam) {
  const fct::Volume ct = waterSlab(100.0);
  fct::FluoroscopyOptions options = absolute();
  options.monochromatic_keV = 60.0;
  const fct::Camera camera = axialCamera();
  auto image = fct::FluoroscopySimulator::render(ct, camera, Eigen::Isometry3d::Identity(), options, 1);
  ASSERT_TRUE(image.ok()) << image.error();
  // Centre pixel: 10 cm of ρ = 1 g/cm³ soft tissue. Off-centre pixel: the slab path grows as 1 / cos θ.
  EXPECT_NEAR(image.value().at(20, 15), std::exp(-muWater60() * 10.0), 1e-6);
  const fct::Ray ray = camera.backProject(Eigen::Vector2d(35, 15));
  const double cosTheta = ray.direction_world.z();
  EXPECT_NEAR(image.value().at(35, 15), std::exp(-muWater60() * 10.0 / cosTheta), 1e-6);
}

TEST(FluoroscopySimulator, PolyenergeticBeamHardensWithThickness) {
  fct::FluoroscopyOptions options = absolute();
  options.tubeVoltage_kvp = 80.0;
  double previousMu = 1e9;
  for (double thickness_mm : {40.0, 100.0, 200.0}) {
    SCOPED_TRACE(thickness_mm);
    auto image = fct::FluoroscopySimulator::render(waterSlab(thickness_mm), axialCamera(), Eigen::Isometry3d::Identity(),
                                                   options, 1);
    ASSERT_TRUE(image.ok()) << image.error();
    const double effectiveMu_per_cm = -std::log(image.value().at(20, 15)) / (thickness_mm / 10.0);
    EXPECT_LT(effectiveMu_per_cm, previousMu);
    // Between water's µ at 80 keV (a hard beam) and at 30 keV (the soft part of an 80 kVp beam).
    EXPECT_GT(effectiveMu_per_cm, muWater60(80.0));
    EXPECT_LT(effectiveMu_per_cm, muWater60(30.0));
    previousMu = effectiveMu_per_cm;
  }
}

TEST(FluoroscopySimulator, NoiseVarianceFollowsTheDose) {
  const fct::Volume ct = waterSlab(100.0);
  fct::FluoroscopyOptions options = absolute();
  options.monochromatic_keV = 60.0;
  const double transmission = std::exp(-muWater60() * 10.0);
  // Near the centre the slab path differs by < 0.5 % between pixels; a monochromatic count k ~ Poisson(N T) gives
  // s = k / N with variance T / N.
  const fct::Camera camera = axialCamera(41, 41, 0.2);
  for (double photons : {2000.0, 8000.0}) {
    SCOPED_TRACE(photons);
    options.photonsPerPixel = photons;
    auto image = fct::FluoroscopySimulator::render(ct, camera, Eigen::Isometry3d::Identity(), options, 7);
    ASSERT_TRUE(image.ok()) << image.error();
    double sum = 0.0, sum2 = 0.0;
    for (float v : image.value().pixels) {
      sum += v;
      sum2 += double(v) * v;
    }
    const double n = double(image.value().pixels.size());
    const double mean = sum / n, variance = sum2 / n - mean * mean;
    EXPECT_NEAR(mean, transmission, 4.0 * std::sqrt(transmission / photons / n));
    EXPECT_NEAR(variance / (transmission / photons), 1.0, 0.12);
  }
}

TEST(FluoroscopySimulator, NoiseIsTheSameForAnyThreadCount) {
  fct::FluoroscopyOptions options = absolute();
  options.photonsPerPixel = 500.0;
  const fct::Volume ct = waterSlab(60.0);
  auto many = fct::FluoroscopySimulator::render(ct, axialCamera(), Eigen::Isometry3d::Identity(), options, 3);
  fct::Result<fct::FloatImage> one = fct::fail("not run");
  {
    tbb::global_control single(tbb::global_control::max_allowed_parallelism, 1);
    one = fct::FluoroscopySimulator::render(ct, axialCamera(), Eigen::Isometry3d::Identity(), options, 3);
  }
  ASSERT_TRUE(many.ok() && one.ok());
  EXPECT_EQ(many.value().pixels, one.value().pixels);
  auto otherSeed = fct::FluoroscopySimulator::render(ct, axialCamera(), Eigen::Isometry3d::Identity(), options, 4);
  EXPECT_NE(otherSeed.value().pixels, many.value().pixels);
}

TEST(FluoroscopySimulator, PointSpreadFunctionPreservesTotalSignal) {
  // Calibration spheres in an empty (air) CT: the blur redistributes their shadows but keeps the total.
  const fct::Volume air = fct::Volume::create(Eigen::Vector3i(4, 4, 4), Eigen::Vector3d::Constant(2.0),
                                              Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity(), -1000.0f)
                              .value();
  fct::FluoroscopyOptions options = absolute();
  options.calibrationSpheres = true;
  options.sphereSpacing_mm = 20.0;
  options.sphereRadius_mm = 2.0;
  const fct::Camera camera = axialCamera(80, 60, 0.5);
  auto sharp = fct::FluoroscopySimulator::render(air, camera, Eigen::Isometry3d::Identity(), options, 1);
  options.psfSigma_px = 2.0;
  auto blurred = fct::FluoroscopySimulator::render(air, camera, Eigen::Isometry3d::Identity(), options, 1);
  ASSERT_TRUE(sharp.ok() && blurred.ok()) << sharp.error() << blurred.error();
  double sharpSum = 0.0, blurredSum = 0.0, sharpMin = 1.0, blurredMin = 1.0;
  for (std::size_t i = 0; i < sharp.value().pixels.size(); ++i) {
    sharpSum += 1.0 - sharp.value().pixels[i];
    blurredSum += 1.0 - blurred.value().pixels[i];
    sharpMin = std::min(sharpMin, double(sharp.value().pixels[i]));
    blurredMin = std::min(blurredMin, double(blurred.value().pixels[i]));
  }
  ASSERT_GT(sharpSum, 10.0);  // the spheres are there
  EXPECT_NEAR(blurredSum / sharpSum, 1.0, 1e-4);
  EXPECT_GT(blurredMin, sharpMin + 0.05);  // and blurred
}

TEST(FluoroscopySimulator, MetalObjectDarkensItsPixels) {
  const fct::Volume ct = smallPhantom();
  const fct::Camera camera = fct::Camera::lookingAt(Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity(), 800.0,
                                                    1000.0, 96, 72, 2.5);
  fct::FluoroscopyOptions options = absolute();
  auto plain = fct::FluoroscopySimulator::render(ct, camera, Eigen::Isometry3d::Identity(), options, 1);
  options.kwireCount = 1;
  options.screwCount = 1;
  auto withMetal = fct::FluoroscopySimulator::render(ct, camera, Eigen::Isometry3d::Identity(), options, 1);
  ASSERT_TRUE(plain.ok() && withMetal.ok()) << plain.error() << withMetal.error();
  int darker = 0, brighter = 0;
  for (std::size_t i = 0; i < plain.value().pixels.size(); ++i) {
    const double ratio = withMetal.value().pixels[i] / plain.value().pixels[i];
    if (ratio < 0.7) ++darker;
    if (ratio > 1.0 + 1e-6) ++brighter;
  }
  EXPECT_GT(darker, 10);
  EXPECT_EQ(brighter, 0);
}

TEST(FluoroscopySimulator, GasPocketBrightensItsPixels) {
  const fct::Volume ct = smallPhantom();
  const fct::Camera camera = fct::Camera::lookingAt(Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity(), 800.0,
                                                    1000.0, 96, 72, 2.5);
  fct::FluoroscopyOptions options = absolute();
  auto plain = fct::FluoroscopySimulator::render(ct, camera, Eigen::Isometry3d::Identity(), options, 1);
  options.gasPocketCount = 2;
  auto withGas = fct::FluoroscopySimulator::render(ct, camera, Eigen::Isometry3d::Identity(), options, 1);
  ASSERT_TRUE(plain.ok() && withGas.ok()) << plain.error() << withGas.error();
  int brighter = 0, darker = 0;
  for (std::size_t i = 0; i < plain.value().pixels.size(); ++i) {
    const double ratio = withGas.value().pixels[i] / plain.value().pixels[i];
    if (ratio > 1.2) ++brighter;
    if (ratio < 1.0 - 1e-6) ++darker;
  }
  EXPECT_GT(brighter, 10);
  EXPECT_EQ(darker, 0);
}

TEST(FluoroscopySimulator, CollimatorZeroesOutsideItsCircle) {
  fct::FluoroscopyOptions options = absolute();
  options.collimatorRadiusFraction = 0.8;
  auto image = fct::FluoroscopySimulator::render(waterSlab(40.0), axialCamera(), Eigen::Isometry3d::Identity(), options, 1);
  ASSERT_TRUE(image.ok()) << image.error();
  EXPECT_EQ(image.value().at(0, 0), 0.0f);
  EXPECT_EQ(image.value().at(40, 30), 0.0f);
  EXPECT_EQ(image.value().at(20, 2), 0.0f);   // 13 px from the centre, radius 0.8 * 15.5 = 12.4 px
  EXPECT_GT(image.value().at(20, 15), 0.1f);
  EXPECT_GT(image.value().at(20, 4), 0.1f);   // 11 px from the centre
}

TEST(FluoroscopySimulator, AutomaticExposureMapsTheReferenceLevelToTheGain) {
  fct::FluoroscopyOptions options;
  options.gain = 40000.0;
  options.offset = 100.0;
  auto image = fct::FluoroscopySimulator::render(waterSlab(100.0), axialCamera(), Eigen::Isometry3d::Identity(), options, 1);
  ASSERT_TRUE(image.ok()) << image.error();
  std::vector<float> sorted = image.value().pixels;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_NEAR(sorted[static_cast<std::size_t>(0.99 * (sorted.size() - 1))], 40100.0f, 1.0f);
  options.gamma = 0.5;
  auto gammaImage = fct::FluoroscopySimulator::render(waterSlab(100.0), axialCamera(), Eigen::Isometry3d::Identity(), options, 1);
  ASSERT_TRUE(gammaImage.ok());
  const double s = (image.value().at(20, 15) - 100.0) / 40000.0;
  EXPECT_NEAR(gammaImage.value().at(20, 15), 100.0 + 40000.0 * std::sqrt(s), 0.05);
}

TEST(FluoroscopySimulator, WritesACaseWithSpheresDistortionFieldAndParameters) {
  const fct::Volume ct = smallPhantom();
  fct::StandardViewOptions viewOptions;
  viewOptions.count = 2;
  viewOptions.cols = 120;
  viewOptions.rows = 90;
  viewOptions.pixelSpacing_mm = 2.4;
  const auto views = fct::StandardViews::build(Eigen::Vector3d::Zero(), viewOptions).value();
  fct::FluoroscopyOptions options;
  options.calibrationSpheres = true;
  options.pincushion = 0.03;
  options.kwireCount = 1;
  options.photonsPerPixel = 1000.0;
  const auto dir = fct::test::scratchDir() / "case";
  auto simulated = fct::FluoroscopySimulator::writeCase(ct, views, Eigen::Isometry3d::Identity(), options, dir, "phantom");
  ASSERT_TRUE(simulated.ok()) << simulated.error();
  auto read = fct::ViewFile::read(dir / "views.json");
  ASSERT_TRUE(read.ok()) << read.error();
  ASSERT_EQ(read.value().size(), 2u);
  EXPECT_FALSE(read.value()[0].calibrationSpheres.empty());
  for (const auto& view : read.value()) {
    EXPECT_TRUE(std::filesystem::exists(view.imagePath));
    EXPECT_TRUE(std::filesystem::exists(dir / (view.name + "_distortion_dcol.nrrd")));
    EXPECT_TRUE(std::filesystem::exists(dir / (view.name + "_distortion_drow.nrrd")));
  }
  EXPECT_TRUE(std::filesystem::exists(dir / "truth_pose.json"));
  std::ifstream file(dir / "simulation.json");
  const std::string text((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("\"model\": \"physical\""), std::string::npos);
  EXPECT_NE(text.find("\"kind\": \"kwire\""), std::string::npos);
  EXPECT_NE(text.find("\"pincushion\": 0.03"), std::string::npos);
}

TEST(FluoroscopySimulator, WritesAGridPlateImagePerViewAndNoInputDewarpFile) {
  const fct::Volume ct = smallPhantom();
  fct::StandardViewOptions viewOptions;
  viewOptions.count = 2;
  viewOptions.cols = 120;
  viewOptions.rows = 90;
  viewOptions.pixelSpacing_mm = 1.0;
  auto views = fct::StandardViews::build(Eigen::Vector3d::Zero(), viewOptions).value();
  views[0].dewarpPath = fct::test::scratchDir() / "other_intensifier.dewarp.json";
  fct::FluoroscopyOptions options;
  options.pincushion = 0.03;
  options.gridPitch_mm = 10.0;
  const auto dir = fct::test::scratchDir() / "case";
  auto simulated = fct::FluoroscopySimulator::writeCase(ct, views, Eigen::Isometry3d::Identity(), options, dir, "phantom");
  ASSERT_TRUE(simulated.ok()) << simulated.error();
  for (const auto& view : views) EXPECT_TRUE(std::filesystem::exists(dir / (view.name + "_grid.png"))) << view.name;
  const auto written = fct::ViewFile::read(dir / "views.json");
  ASSERT_TRUE(written.ok()) << written.error();
  EXPECT_TRUE(written.value()[0].dewarpPath.empty());
  // The plate alone, rendered without a CT: its steel beads are dark spots; a zero pitch is refused.
  auto plate = fct::FluoroscopySimulator::renderGridPlate(views[1].camera, options, 1);
  ASSERT_TRUE(plate.ok()) << plate.error();
  float darkest = plate.value().pixels[0], brightest = darkest;
  for (float v : plate.value().pixels) {
    darkest = std::min(darkest, v);
    brightest = std::max(brightest, v);
  }
  EXPECT_LT(darkest, 0.8f * brightest) << "the beads show";
  options.gridPitch_mm = 0.0;
  EXPECT_FALSE(fct::FluoroscopySimulator::renderGridPlate(views[1].camera, options, 1).ok());
}

TEST(FluoroscopySimulator, ScatterHazeAddsItsFractionOfTheBlurredPrimary) {
  // Behind a wide uniform slab the primary is flat, so its blur is itself: the haze adds f times it.
  const fct::Volume ct = waterSlab(100.0);
  fct::FluoroscopyOptions options = absolute();
  options.monochromatic_keV = 60.0;
  const fct::Camera camera = axialCamera(41, 31, 0.5);
  const float primary = fct::FluoroscopySimulator::render(ct, camera, Eigen::Isometry3d::Identity(), options, 1)
                            .value()
                            .at(20, 15);
  options.scatterToPrimary = 0.2;
  options.scatterSigma_mm = 2.0;
  const float hazy = fct::FluoroscopySimulator::render(ct, camera, Eigen::Isometry3d::Identity(), options, 1)
                         .value()
                         .at(20, 15);
  EXPECT_NEAR(hazy, 1.2f * primary, 1e-3 * primary);
}

TEST(FluoroscopySimulator, VoxelBoxPatientMatchesTheContinuousOneInsideAUniformSlab) {
  const fct::Volume ct = waterSlab(100.0);
  fct::FluoroscopyOptions options = absolute();
  options.monochromatic_keV = 60.0;
  const float continuous =
      fct::FluoroscopySimulator::render(ct, axialCamera(), Eigen::Isometry3d::Identity(), options, 1).value().at(20, 15);
  options.patient = fct::PatientModel::VoxelBoxes;
  const float boxes =
      fct::FluoroscopySimulator::render(ct, axialCamera(), Eigen::Isometry3d::Identity(), options, 1).value().at(20, 15);
  EXPECT_NEAR(continuous, boxes, 1e-6);
}

TEST(FluoroscopySimulator, RejectsBadInput) {
  const fct::Volume ct = waterSlab(40.0);
  const fct::Camera camera = axialCamera();
  Eigen::Isometry3d scaled = Eigen::Isometry3d::Identity();
  scaled.linear() *= 2.0;
  auto notRigid = fct::FluoroscopySimulator::render(ct, camera, scaled, {}, 1);
  ASSERT_FALSE(notRigid.ok());
  EXPECT_NE(notRigid.error().find("rigid"), std::string::npos) << notRigid.error();
  fct::FluoroscopyOptions badKvp;
  badKvp.tubeVoltage_kvp = 200.0;
  EXPECT_FALSE(fct::FluoroscopySimulator::render(ct, camera, Eigen::Isometry3d::Identity(), badKvp, 1).ok());
  fct::FluoroscopyOptions badDose;
  badDose.photonsPerPixel = -5.0;
  EXPECT_FALSE(fct::FluoroscopySimulator::render(ct, camera, Eigen::Isometry3d::Identity(), badDose, 1).ok());
  fct::FluoroscopyOptions badGamma;
  badGamma.gamma = 0.0;
  EXPECT_FALSE(fct::FluoroscopySimulator::render(ct, camera, Eigen::Isometry3d::Identity(), badGamma, 1).ok());
  fct::FluoroscopyOptions badScatter;
  badScatter.scatterToPrimary = -0.1;
  EXPECT_FALSE(fct::FluoroscopySimulator::render(ct, camera, Eigen::Isometry3d::Identity(), badScatter, 1).ok());
  fct::FluoroscopyOptions extendedBoxes;
  extendedBoxes.patient = fct::PatientModel::VoxelBoxes;
  extendedBoxes.patientExtension_mm = 10.0;
  EXPECT_FALSE(fct::FluoroscopySimulator::render(ct, camera, Eigen::Isometry3d::Identity(), extendedBoxes, 1).ok());
  fct::FluoroscopyOptions noBone;
  noBone.kwireCount = 1;
  EXPECT_FALSE(fct::FluoroscopySimulator::render(ct, camera, Eigen::Isometry3d::Identity(), noBone, 1).ok());

  // An output folder below a regular file cannot be created; nothing is written.
  const auto dir = fct::test::scratchDir();
  { std::ofstream(dir / "file") << "x"; }
  fct::ViewSpec view;
  view.name = "ap";
  view.camera = camera;
  auto unwritable = fct::FluoroscopySimulator::writeCase(ct, {view}, Eigen::Isometry3d::Identity(), {}, dir / "file" / "case", "slab");
  ASSERT_FALSE(unwritable.ok());
  EXPECT_NE(unwritable.error().find("cannot create output folder"), std::string::npos) << unwritable.error();
  EXPECT_FALSE(fct::FluoroscopySimulator::writeCase(ct, {}, Eigen::Isometry3d::Identity(), {}, dir / "empty", "slab").ok());
  EXPECT_FALSE(std::filesystem::exists(dir / "empty"));
}

TEST(FluoroscopySimulator, SequenceFramesAreTheSingleRendersAtEachPoseWithTheirOwnNoise) {
  const fct::Volume ct = smallPhantom();
  const std::vector<fct::Camera> cameras{axialCamera(24, 20, 4.0), axialCamera(20, 16, 5.0)};
  std::vector<Eigen::Isometry3d> poses(3, Eigen::Isometry3d::Identity());
  poses[1].pretranslate(Eigen::Vector3d(4.0, 0.0, 0.0));
  poses[2].rotate(Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitY()));
  fct::FluoroscopyOptions options;
  options.photonsPerPixel = 2000.0;
  std::vector<std::vector<fct::FloatImage>> frames;
  const fct::Status rendered = fct::FluoroscopySimulator::renderSequence(
      ct, cameras, poses, options, 7, false, [&](int frame, std::vector<fct::FloatImage> images) -> fct::Status {
        EXPECT_EQ(frame, static_cast<int>(frames.size()));
        frames.push_back(std::move(images));
        return fct::Ok{};
      });
  ASSERT_TRUE(rendered.ok()) << rendered.error();
  ASSERT_EQ(frames.size(), 3u);
  for (int k = 0; k < 3; ++k) {
    for (int n = 0; n < 2; ++n) {
      const auto single = fct::FluoroscopySimulator::render(ct, cameras[n], poses[k], options, 7 + 2 * k + n);
      ASSERT_TRUE(single.ok()) << single.error();
      EXPECT_EQ(frames[k][n].pixels, single.value().pixels) << "frame " << k << " view " << n;
    }
  }
  // Same pose, another frame: only the noise differs.
  const auto again = fct::FluoroscopySimulator::render(ct, cameras[0], poses[0], options, 7 + 2);
  EXPECT_NE(again.value().pixels, frames[0][0].pixels);
}

TEST(FluoroscopySimulator, SequenceObjectsFixedInTheWorldStayWhileTheBoneMoves) {
  const fct::Volume ct = smallPhantom();
  const std::vector<fct::Camera> cameras{axialCamera(40, 40, 3.0)};
  std::vector<Eigen::Isometry3d> poses(2, Eigen::Isometry3d::Identity());
  poses[1].pretranslate(Eigen::Vector3d(0.0, 10.0, 0.0));
  fct::FluoroscopyOptions options;
  options.kwireCount = 2;
  const auto renderAll = [&](bool fixed) {
    std::vector<fct::FloatImage> out;
    const fct::Status ok = fct::FluoroscopySimulator::renderSequence(
        ct, cameras, poses, options, 1, fixed, [&](int, std::vector<fct::FloatImage> images) -> fct::Status {
          out.push_back(std::move(images.front()));
          return fct::Ok{};
        });
    EXPECT_TRUE(ok.ok()) << ok.error();
    return out;
  };
  const std::vector<fct::FloatImage> moving = renderAll(false);
  const std::vector<fct::FloatImage> fixed = renderAll(true);
  ASSERT_EQ(moving.size(), 2u);
  ASSERT_EQ(fixed.size(), 2u);
  EXPECT_EQ(fixed[0].pixels, moving[0].pixels) << "at the first pose the objects are where they were placed";
  EXPECT_NE(fixed[1].pixels, moving[1].pixels) << "later, fixed objects are not carried along with the bone";
  // Without objects the two modes are the same image.
  options.kwireCount = 0;
  EXPECT_EQ(renderAll(true)[1].pixels, renderAll(false)[1].pixels);
}

TEST(FluoroscopySimulator, SequenceWithoutPosesOrWithABadPoseIsRefused) {
  const fct::Volume ct = smallPhantom();
  const auto sink = [](int, std::vector<fct::FloatImage>) -> fct::Status { return fct::Ok{}; };
  EXPECT_FALSE(fct::FluoroscopySimulator::renderSequence(ct, {axialCamera()}, {}, {}, 1, false, sink).ok());
  std::vector<Eigen::Isometry3d> poses(2, Eigen::Isometry3d::Identity());
  poses[1].linear() *= 2.0;
  const fct::Status bad = fct::FluoroscopySimulator::renderSequence(ct, {axialCamera()}, poses, {}, 1, false, sink);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().find("frame 1"), std::string::npos) << bad.error();
}
