#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "Simulation/FluoroscopySimulator.h"
#include "Simulation/IntensifierDistortion.h"
#include "XrayPrep/DewarpCalibrator.h"
#include "XrayPrep/XrayDewarper.h"

namespace {

constexpr int kCols = 384;
constexpr int kRows = 288;
constexpr double kPixel_mm = 0.8;

/// A C-arm camera of a 384x288 detector with 0.8 mm pixels, 1000 mm from the source, principal point at the centre.
fct::Camera detectorCamera() {
  fct::CameraIntrinsics in;
  in.cols = kCols;
  in.rows = kRows;
  in.pixelSpacing_mm = {kPixel_mm, kPixel_mm};
  in.sourceToDetector_mm = 1000.0;
  in.principalPoint_px = {0.5 * (kCols - 1), 0.5 * (kRows - 1)};
  return fct::Camera::create(in, Eigen::Isometry3d::Identity()).value();
}

/// The simulator's options for an intensifier with pincushion k and S-distortion s (noise, blur, vignetting on).
fct::FluoroscopyOptions intensifier(double pincushion, double sDistortion_deg, double gridPitch_mm) {
  fct::FluoroscopyOptions o;
  o.pincushion = pincushion;
  o.sDistortion_deg = sDistortion_deg;
  o.photonsPerPixel = 20000.0;
  o.psfSigma_px = 0.7;
  o.vignetting = 0.2;
  o.gridPitch_mm = gridPitch_mm;
  return o;
}

/// The simulated grid plate image of that intensifier.
fct::FloatImage gridImage(const fct::FluoroscopyOptions& options) {
  auto image = fct::FluoroscopySimulator::renderGridPlate(detectorCamera(), options, 7);
  EXPECT_TRUE(image.ok()) << image.error();
  return image.ok() ? image.value() : fct::FloatImage::filled(kCols, kRows, 1.0f);
}

fct::Result<fct::DewarpCalibrationResult> calibrate(const fct::FloatImage& image, double pitch_mm, int degree = 0) {
  fct::DewarpCalibrationOptions options;
  options.pitch_mm = pitch_mm;
  options.pixelSpacing_mm = kPixel_mm;
  options.degree = degree;
  return fct::DewarpCalibrator(options).calibrate(image, fct::ValidMask::allValid(image.cols, image.rows));
}

/// Largest |field(d) − truth(d)| over distorted pixels d every 4 px inside the convex hull of the beads used (the
/// calibrated field of view).
double largestErrorAgainstTruth(const fct::DewarpCalibrationResult& result, const fct::IntensifierDistortion& truth) {
  std::vector<cv::Point2f> beads, hull;
  for (const fct::DewarpBead& bead : result.beads) {
    if (bead.used) beads.emplace_back(static_cast<float>(bead.distorted_px.x()), static_cast<float>(bead.distorted_px.y()));
  }
  cv::convexHull(beads, hull);
  double largest = 0.0;
  for (int row = 0; row < kRows; row += 4) {
    for (int col = 0; col < kCols; col += 4) {
      if (cv::pointPolygonTest(hull, cv::Point2f(static_cast<float>(col), static_cast<float>(row)), false) < 0) continue;
      const Eigen::Vector2d d(col, row);
      largest = std::max(largest, (result.field.ideal(d) - truth.undistort(d)).norm());
    }
  }
  return largest;
}

}  // namespace

TEST(DewarpCalibrator, PincushionAndSDistortionAreUndoneWithinAThirdOfAPixel) {
  const fct::FluoroscopyOptions options = intensifier(0.06, 4.0, 10.0);
  auto result = calibrate(gridImage(options), 10.0);
  ASSERT_TRUE(result.ok()) << result.error();
  const fct::DewarpCalibration& r = result.value().record;
  EXPECT_GT(r.beadCount, 500);
  EXPECT_LE(r.rmsResidual_px, 0.3);
  EXPECT_LE(r.maxResidual_px, 0.3);
  // Plate 20 mm in front of a detector 1000 mm from the source: magnification 1000 / 980.
  EXPECT_NEAR(r.magnification, 1000.0 / 980.0, 0.002);
  EXPECT_NEAR(r.latticeRotation_deg, 0.0, 0.03);
  const auto truth = fct::IntensifierDistortion::create(kCols, kRows, 0.06, 4.0).value();
  EXPECT_LE(largestErrorAgainstTruth(result.value(), truth), 0.3);
}

TEST(DewarpCalibrator, AnUndistortedGridGivesANearIdentityField) {
  auto result = calibrate(gridImage(intensifier(0.0, 0.0, 10.0)), 10.0, 3);
  ASSERT_TRUE(result.ok()) << result.error();
  EXPECT_EQ(result.value().field.degree(), 3);
  EXPECT_LE(result.value().record.rmsResidual_px, 0.15);
  for (const Eigen::Vector2d& d : {Eigen::Vector2d(10, 10), Eigen::Vector2d(370, 280), Eigen::Vector2d(200, 20)}) {
    EXPECT_LT((result.value().field.ideal(d) - d).norm(), 0.15) << d.transpose();
  }
}

TEST(DewarpCalibrator, ABlankImageHasNoGrid) {
  auto result = calibrate(fct::FloatImage::filled(kCols, kRows, 40000.0f), 10.0);
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.error().find("no calibration grid found"), std::string::npos) << result.error();
}

TEST(DewarpCalibrator, ACoarseGridHasTooFewBeads) {
  auto result = calibrate(gridImage(intensifier(0.03, 0.0, 60.0)), 60.0);
  ASSERT_FALSE(result.ok());
  EXPECT_TRUE(result.error().find("too few beads") != std::string::npos ||
              result.error().find("no calibration grid found") != std::string::npos)
      << result.error();
}

TEST(DewarpCalibrator, AWrongPitchIsCaughtByTheMagnification) {
  const fct::FloatImage grid = gridImage(intensifier(0.03, 2.0, 10.0));
  auto result = calibrate(grid, 20.0);
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.error().find("magnification"), std::string::npos) << result.error();
  EXPECT_NE(result.error().find("check the pitch"), std::string::npos) << result.error();
  EXPECT_FALSE(calibrate(grid, -1.0).ok());
  EXPECT_FALSE(calibrate(grid, 10.0, 12).ok());
}

TEST(XrayDewarper, ResamplesADistortedGridOntoTheIdealLatticeAndMarksPixelsWithoutSource) {
  const fct::FluoroscopyOptions options = intensifier(0.06, 4.0, 10.0);
  const fct::FloatImage grid = gridImage(options);
  auto result = calibrate(grid, 10.0);
  ASSERT_TRUE(result.ok()) << result.error();
  fct::XrayImage xray;
  xray.cols = grid.cols;
  xray.rows = grid.rows;
  xray.pixels = grid.pixels;
  auto dewarped = fct::XrayDewarper::apply(xray, result.value().field);
  ASSERT_TRUE(dewarped.ok()) << dewarped.error();
  // Pincushion pushes the corners outwards: the ideal image's corners have no source pixel.
  ASSERT_EQ(dewarped.value().fovMask.size(), grid.pixels.size());
  EXPECT_EQ(dewarped.value().fovMask.front(), 0);
  EXPECT_EQ(dewarped.value().fovMask[static_cast<std::size_t>(kRows / 2) * kCols + kCols / 2], 1);
  // The dewarped grid's beads sit on an undistorted square lattice: calibrating it again gives a near-identity field.
  fct::DewarpCalibrationOptions again;
  again.pitch_mm = 10.0;
  again.degree = 3;
  auto mask = fct::ValidMask::fromBytes(kCols, kRows, dewarped.value().fovMask);
  ASSERT_TRUE(mask.ok());
  const fct::FloatImage image{kCols, kRows, dewarped.value().pixels};
  auto second = fct::DewarpCalibrator(again).calibrate(image, mask.value());
  ASSERT_TRUE(second.ok()) << second.error();
  EXPECT_LE(second.value().record.rmsResidual_px, 0.15);
  EXPECT_NEAR(second.value().record.latticePitch_px, result.value().record.latticePitch_px, 0.02);
}

TEST(XrayDewarper, IdentityFieldKeepsTheImageAndOtherSizesAreRefused) {
  fct::XrayImage xray;
  xray.cols = 40;
  xray.rows = 30;
  for (int i = 0; i < 40 * 30; ++i) xray.pixels.push_back(static_cast<float>(i % 17));
  auto same = fct::XrayDewarper::apply(xray, fct::DewarpField::identity(40, 30, 3).value());
  ASSERT_TRUE(same.ok()) << same.error();
  EXPECT_EQ(same.value().pixels, xray.pixels);
  EXPECT_EQ(same.value().fovMask, std::vector<std::uint8_t>(40 * 30, 1));
  const auto circles = fct::XrayDewarper::mapCircles({{Eigen::Vector2d(5, 6), 2.0}},
                                                     fct::DewarpField::identity(40, 30, 3).value());
  EXPECT_LT((circles[0].centre_px - Eigen::Vector2d(5, 6)).norm(), 1e-12);
  EXPECT_DOUBLE_EQ(circles[0].radius_px, 2.0);
  auto other = fct::XrayDewarper::apply(xray, fct::DewarpField::identity(80, 60, 3).value());
  ASSERT_FALSE(other.ok());
  EXPECT_NE(other.error().find("calibrated for 80x60"), std::string::npos) << other.error();
}
