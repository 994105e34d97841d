// The metal mask on physically simulated views of the real CTs (continuous patient, 80 kVp, noise; 5 obliquities):
// what it removes from metal-free views, and that it finds K-wires and screws that are not in the CT, printed for
// each view; and the real shoulder fluoroscopy's K-wire. Needs ../shared/data; about 90 s (simulates 20 views).
//
// DISABLED: both fail today. Measured on 2026-12-01 (2-core Debian 12 development machine, shared;
// `fluoroct_logic_tests --gtest_also_run_disabled_tests --gtest_filter='MetalMaskFalse*'`), default threshold 1.5:
// metal-free pelvis views 0.00-0.22 %, metal-free head-phantom views 10.1-21.5 % (the skull's tangent rim is taken
// for metal); with 2 K-wires and 2 screws 2.6-3.7 % (pelvis), 15.7-25.4 % (head); the real shoulder K-wire image
// 0.00 % (its wire is not found). Enable them when the detector separates bone rims from metal.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

#include "Evaluation/StudyRunner.h"
#include "IO/Volume/CtLoader.h"
#include "Image/BoneSurface.h"
#include "Simulation/FluoroscopySimulator.h"
#include "Simulation/StandardViews.h"
#include "TestSupport.h"
#include "TestXrayLoader.h"
#include "XrayPrep/XrayPreparation.h"

namespace {

/// Largest fraction of valid pixels the metal mask (threshold minExcess) removes over the views of `ct` simulated with
/// `kwires` K-wires and `screws` screws; prints each view's fraction.
double largestMetalFraction(const fct::Volume& ct, int kwires, int screws, double minExcess) {
  const Eigen::Isometry3d T_truth = fct::StudyRunner::truthPose(fct::BoneSurface::extract(ct).value());
  fct::StandardViewOptions viewOptions;
  viewOptions.count = 5;
  viewOptions.cols = 192;
  viewOptions.rows = 144;
  viewOptions.pixelSpacing_mm = 1.6;
  const std::vector<fct::ViewSpec> views = fct::StandardViews::build(Eigen::Vector3d::Zero(), viewOptions).value();
  fct::FluoroscopyOptions options;
  options.photonsPerPixel = 10000.0;
  options.psfSigma_px = 0.7;
  options.kwireCount = kwires;
  options.screwCount = screws;
  double largest = 0.0;
  std::printf("  %d K-wires, %d screws, min excess %.1f:", kwires, screws, minExcess);
  for (std::size_t v = 0; v < views.size(); ++v) {
    auto image = fct::FluoroscopySimulator::render(ct, views[v].camera, T_truth, options, 1 + v);
    EXPECT_TRUE(image.ok()) << image.error();
    if (!image) return 1.0;
    fct::XrayImage xray;
    xray.cols = image.value().cols;
    xray.rows = image.value().rows;
    xray.pixels = image.value().pixels;
    xray.camera = views[v].camera;
    fct::XrayPreparationOptions prep;
    prep.metal.minExcess = minExcess;
    auto prepared = fct::XrayPreparation(prep).prepare(xray);
    EXPECT_TRUE(prepared.ok()) << prepared.error();
    if (!prepared) return 1.0;
    std::printf(" %s %.2f %%", views[v].name.c_str(), 100.0 * prepared.value().metalFraction);
    largest = std::max(largest, prepared.value().metalFraction);
  }
  std::printf("\n");
  return largest;
}

}  // namespace

TEST(MetalMaskFalsePositives, DISABLED_MeasuredOnMetalFreeAndMetalViewsOfBothCts) {
  FCT_REQUIRE_DATA("ct/pelvis_totalseg.nii.gz");
  FCT_REQUIRE_DATA("ct/head_phantom_philips_bone");
  const double minExcess = fct::MetalMaskOptions{}.minExcess;
  for (const std::string name : {"ct/pelvis_totalseg.nii.gz", "ct/head_phantom_philips_bone"}) {
    SCOPED_TRACE(name);
    auto ct = fct::CtLoader::load(fct::test::dataDir() / name);
    ASSERT_TRUE(ct.ok()) << ct.error();
    std::printf("%s\n", name.c_str());
    EXPECT_LT(largestMetalFraction(ct.value(), 0, 0, minExcess), 0.005);
    EXPECT_GT(largestMetalFraction(ct.value(), 2, 2, minExcess), 0.001);
  }
}

TEST(MetalMaskFalsePositives, DISABLED_FindsTheRealKWire) {
  FCT_REQUIRE_DATA("xray/rf_shoulder_kwire.dcm");
  const auto xray = fct::test::loadXrayWithDcmtk(fct::test::dataDir() / "xray/rf_shoulder_kwire.dcm");
  ASSERT_TRUE(xray.has_value());
  const auto prepared = fct::XrayPreparation().prepare(*xray);
  ASSERT_TRUE(prepared.ok()) << prepared.error();
  std::printf("real shoulder fluoroscopy: metal mask %.2f %% of the field\n", 100.0 * prepared.value().metalFraction);
  EXPECT_GT(prepared.value().metalFraction, 0.001);
}
