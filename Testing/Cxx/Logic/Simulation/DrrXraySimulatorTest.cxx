#include <gtest/gtest.h>

#include <cmath>

#include "Drr/DrrRendererFactory.h"
#include "IO/Project/PoseFile.h"
#include "IO/Project/ViewFile.h"
#include "IO/Xray/XrayImageFileReader.h"
#include "Simulation/DrrXraySimulator.h"
#include "Simulation/PhantomBuilder.h"
#include "Simulation/StandardViews.h"
#include "TestSupport.h"

namespace {

fct::Volume smallPhantom() {
  fct::PhantomOptions options;
  options.dims = Eigen::Vector3i(48, 48, 36);
  options.spacing_mm = 3.3;
  return fct::PhantomBuilder::build(options).value();
}

std::vector<fct::ViewSpec> smallViews(int count) {
  fct::StandardViewOptions options;
  options.count = count;
  options.cols = 120;
  options.rows = 90;
  options.pixelSpacing_mm = 2.4;
  return fct::StandardViews::build(Eigen::Vector3d::Zero(), options).value();
}

Eigen::Isometry3d somePose() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.rotate(Eigen::AngleAxisd(0.1, Eigen::Vector3d(1, 2, 0).normalized()));
  T.pretranslate(Eigen::Vector3d(4.0, -3.0, 2.0));
  return T;
}

/// Mean and variance of an image's pixels.
std::pair<double, double> meanAndVariance(const fct::FloatImage& image) {
  double sum = 0.0, sumSquares = 0.0;
  for (float v : image.pixels) {
    sum += v;
    sumSquares += double(v) * v;
  }
  const double n = static_cast<double>(image.pixels.size());
  return {sum / n, sumSquares / n - (sum / n) * (sum / n)};
}

}  // namespace

TEST(DrrXraySimulator, WrittenPngReadsBackAsTheDrr) {
  const fct::Volume ct = smallPhantom();
  const auto views = smallViews(2);
  const auto dir = fct::test::scratchDir() / "case";
  fct::XraySimulationOptions options;
  auto simulated = fct::DrrXraySimulator::writeCase(ct, views, somePose(), options, dir, "phantom");
  ASSERT_TRUE(simulated.ok()) << simulated.error();

  auto drrVolume = fct::DrrVolume::create(ct);
  ASSERT_TRUE(drrVolume.ok());
  auto renderer = fct::DrrRendererFactory::create(std::make_shared<const fct::DrrVolume>(std::move(drrVolume).value()));
  ASSERT_TRUE(renderer.ok());
  auto viewFile = fct::ViewFile::read(dir / "views.json");
  ASSERT_TRUE(viewFile.ok()) << viewFile.error();
  ASSERT_EQ(viewFile.value().size(), 2u);
  for (std::size_t n = 0; n < views.size(); ++n) {
    SCOPED_TRACE(views[n].name);
    EXPECT_EQ(viewFile.value()[n].imagePath, dir / (views[n].name + ".png"));
    auto xray = fct::XrayImageFileReader::read(viewFile.value()[n].imagePath);
    ASSERT_TRUE(xray.ok()) << xray.error();
    EXPECT_EQ(xray.value().bitsStored, 16);
    auto drr = renderer.value()->render(views[n].camera, somePose(), 0);
    ASSERT_TRUE(drr.ok());
    ASSERT_EQ(xray.value().pixels.size(), drr.value().pixels.size());
    double worst = 0.0;
    for (std::size_t i = 0; i < drr.value().pixels.size(); ++i) {
      const double I = xray.value().pixels[i];
      ASSERT_GT(I, 0.0);
      const double p = -std::log(I / options.unattenuatedIntensity);
      // Rounding to an integer changes p by at most 0.5 / I.
      worst = std::max(worst, std::abs(p - drr.value().pixels[i]) / (0.5 / I + 1e-6));
    }
    EXPECT_LE(worst, 1.0);
    EXPECT_GT(simulated.value().maxLineIntegral[n], 1.0);
  }
  auto pose = fct::PoseFile::read(dir / "truth_pose.json");
  ASSERT_TRUE(pose.ok()) << pose.error();
  EXPECT_LT((pose.value().matrix() - somePose().matrix()).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_TRUE(std::filesystem::exists(dir / "simulation.json"));
}

TEST(DrrXraySimulator, NoiseVarianceFollowsThePhotonCount) {
  const double I0 = 60000.0;
  for (const double p : {0.0, 2.0, 5.0}) {  // 5.0 exercises small Poisson means (N e^-p < 10 for N = 1000)
    const fct::FloatImage flat = fct::FloatImage::filled(200, 200, static_cast<float>(p));
    for (const double photons : {1000.0, 16000.0}) {
      SCOPED_TRACE(::testing::Message() << "p " << p << ", photons " << photons);
      auto noisy = fct::DrrXraySimulator::intensityFromDrr(flat, I0, photons, 3);
      ASSERT_TRUE(noisy.ok()) << noisy.error();
      const auto [mean, variance] = meanAndVariance(noisy.value());
      const double expectedMean = I0 * std::exp(-p);
      EXPECT_NEAR(mean / expectedMean, 1.0, 0.01 + 5.0 / std::sqrt(photons * std::exp(-p) * 40000.0));
      EXPECT_NEAR(variance / (I0 * I0 * std::exp(-p) / photons), 1.0, 0.05);
    }
  }
}

TEST(DrrXraySimulator, NoiseIsSeeded) {
  const fct::FloatImage flat = fct::FloatImage::filled(64, 48, 1.0f);
  auto a = fct::DrrXraySimulator::intensityFromDrr(flat, 60000.0, 500.0, 9);
  auto b = fct::DrrXraySimulator::intensityFromDrr(flat, 60000.0, 500.0, 9);
  auto c = fct::DrrXraySimulator::intensityFromDrr(flat, 60000.0, 500.0, 10);
  auto clean = fct::DrrXraySimulator::intensityFromDrr(flat, 60000.0, 0.0, 9);
  ASSERT_TRUE(a.ok() && b.ok() && c.ok() && clean.ok());
  EXPECT_EQ(a.value().pixels, b.value().pixels);
  EXPECT_NE(a.value().pixels, c.value().pixels);
  EXPECT_NEAR(clean.value().pixels[0], 60000.0 * std::exp(-1.0), 1e-2);
  EXPECT_EQ(meanAndVariance(clean.value()).second < 1e-6, true);
}

TEST(DrrXraySimulator, RejectsBadInputsAndWritesNothing) {
  const fct::FloatImage flat = fct::FloatImage::filled(8, 8, 1.0f);
  EXPECT_FALSE(fct::DrrXraySimulator::intensityFromDrr(fct::FloatImage{}, 60000.0, 0.0, 1).ok());
  EXPECT_FALSE(fct::DrrXraySimulator::intensityFromDrr(flat, 0.0, 0.0, 1).ok());
  EXPECT_FALSE(fct::DrrXraySimulator::intensityFromDrr(flat, 60000.0, -1.0, 1).ok());
  fct::FloatImage negative = flat;
  negative.pixels[5] = -0.5f;
  EXPECT_FALSE(fct::DrrXraySimulator::intensityFromDrr(negative, 60000.0, 0.0, 1).ok());

  const fct::Volume ct = smallPhantom();
  const auto dir = fct::test::scratchDir() / "case";
  fct::XraySimulationOptions options;
  auto none = fct::DrrXraySimulator::writeCase(ct, {}, somePose(), options, dir, "phantom");
  EXPECT_FALSE(none.ok());
  auto views = smallViews(1);
  views[0].name = "../escape";
  auto badName = fct::DrrXraySimulator::writeCase(ct, views, somePose(), options, dir, "phantom");
  ASSERT_FALSE(badName.ok());
  EXPECT_NE(badName.error().find("../escape"), std::string::npos) << badName.error();
  options.unattenuatedIntensity = 70000.0;
  auto tooBright = fct::DrrXraySimulator::writeCase(ct, smallViews(1), somePose(), options, dir, "phantom");
  ASSERT_FALSE(tooBright.ok());
  EXPECT_NE(tooBright.error().find("65535"), std::string::npos) << tooBright.error();
  options = {};
  Eigen::Isometry3d notRigid = somePose();
  notRigid.matrix()(0, 0) = 2.0;
  EXPECT_FALSE(fct::DrrXraySimulator::writeCase(ct, smallViews(1), notRigid, options, dir, "phantom").ok());
  EXPECT_FALSE(std::filesystem::exists(dir)) << "a failed simulation must write nothing";
}
