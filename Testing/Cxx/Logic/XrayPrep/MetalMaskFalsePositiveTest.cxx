// The metal mask on physically simulated views (continuous patient, 80 kVp, 10,000 photons per pixel, PSF 0.7 px;
// the 5 standard obliquities AP, lateral, oblique 45/30/60 on a 192x144 detector of 1.6 mm pixels) of the built-in
// phantom and, when ../shared/data is there, of the head phantom and pelvis CTs: once reviewed against a DRR near the
// truth (MetalMaskReview, as registration does after its first stage, the DRR with the case's default bone contrast),
// it removes less than 0.5 % of each metal-free view's pixels whose rays the CT covers (CutFaceRayMask, 5 mm: elsewhere
// the X-ray shows anatomy the CT lacks and the review cannot judge a piece), and the detector covers most of the pixels
// of K-wires and screws that are not in the CT (the pixels whose line integral the tools raise by more than 0.5 over
// the metal-free view with the same noise).
// The detector's own fraction and the reviewed fraction of the whole view are printed beside it. The per-view table of
// docs/evaluation.md comes from the disabled MetalMaskStudy test (both CTs, also at 0.8 mm pixels; about 5 min). The
// real shoulder fluoroscopy's K-wire stays disabled: the contrast-processed image's wire stands only ~0.5 above its
// surroundings.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "Drr/CutFaceRayMask.h"
#include "Drr/DrrVolume.h"
#include "Drr/SiddonRayCaster.h"
#include "Evaluation/PoseOffset.h"
#include "Evaluation/StudyRunner.h"
#include "IO/Volume/CtLoader.h"
#include "Image/BoneSurface.h"
#include "Registration/RegistrationCase.h"
#include "Simulation/FluoroscopySimulator.h"
#include "Simulation/PhantomBuilder.h"
#include "Simulation/StandardViews.h"
#include "TestSupport.h"
#include "TestXrayLoader.h"
#include "XrayPrep/MetalMaskDetector.h"
#include "XrayPrep/MetalMaskReview.h"
#include "XrayPrep/XrayPreparation.h"

namespace {

/// What the metal mask does on one view.
struct ViewMeasure {
  std::string view;
  double falsePositive = 0.0;  ///< fraction of the metal-free view's valid pixels the detector masks
  double reviewedFalsePositive = 0.0;  ///< ... still masked after the review against a DRR near the truth
  double comparedFalsePositive = 0.0;  ///< ... of the pixels whose rays the CT covers (the DRR can explain)
  double coverage = 0.0;       ///< fraction of the tool pixels masked in the view with tools (1 without tools)
  std::size_t toolPixels = 0;  ///< valid pixels the tools raise by more than 0.5
};

/// The level-0 line integrals and valid mask of a simulated view, prepared without the metal exclusion.
struct Prepared {
  fct::FloatImage lineIntegrals;
  fct::ValidMask mask;
};

Prepared prepare(const fct::FloatImage& image, const fct::Camera& camera) {
  fct::XrayImage xray;
  xray.cols = image.cols;
  xray.rows = image.rows;
  xray.pixels = image.pixels;
  xray.camera = camera;
  fct::XrayPreparationOptions options;
  options.excludeMetal = false;
  auto prepared = fct::XrayPreparation(options).prepare(xray);
  EXPECT_TRUE(prepared.ok()) << prepared.error();
  if (!prepared) return {};
  const fct::PyramidLevel& level = prepared.value().pyramid.level(0);
  return {level.image, level.mask};
}

/// The images of the 5 standard views (noise seeds 1..5) of `ct` at `T_truth`, with or without 2 K-wires and 2 screws.
std::vector<fct::FloatImage> renderViews(const fct::Volume& ct, const std::vector<fct::Camera>& cameras,
                                         const Eigen::Isometry3d& T_truth, bool tools) {
  fct::FluoroscopyOptions options;
  options.photonsPerPixel = 10000.0;
  options.psfSigma_px = 0.7;
  options.kwireCount = tools ? 2 : 0;
  options.screwCount = tools ? 2 : 0;
  auto images = fct::FluoroscopySimulator::renderViews(ct, cameras, T_truth, options, 1);
  EXPECT_TRUE(images.ok()) << images.error();
  return images ? std::move(images).value() : std::vector<fct::FloatImage>{};
}

/// The metal mask's false positives on the metal-free views of `ct` and, with `coverage`, its coverage of 2 K-wires
/// and 2 screws (tool pixels: those the tools raise by more than 0.5 over the metal-free view with the same noise
/// seed), on the 5 standard views of a cols x rows detector of `spacing_mm` pixels; one table line printed per view.
std::vector<ViewMeasure> measureViews(const fct::Volume& ct, const std::string& label, int cols, int rows,
                                      double spacing_mm, bool coverage) {
  const fct::BoneSurface bone = fct::BoneSurface::extract(ct).value();
  const Eigen::Isometry3d T_truth = fct::StudyRunner::truthPose(bone);
  fct::StandardViewOptions viewOptions;
  viewOptions.count = 5;
  viewOptions.cols = cols;
  viewOptions.rows = rows;
  viewOptions.pixelSpacing_mm = spacing_mm;
  const std::vector<fct::ViewSpec> views = fct::StandardViews::build(Eigen::Vector3d::Zero(), viewOptions).value();
  std::vector<fct::Camera> cameras;
  for (const fct::ViewSpec& view : views) cameras.push_back(view.camera);
  const std::vector<fct::FloatImage> freeImages = renderViews(ct, cameras, T_truth, false);
  const std::vector<fct::FloatImage> toolImages = coverage ? renderViews(ct, cameras, T_truth, true) : freeImages;
  if (freeImages.size() != views.size() || toolImages.size() != views.size()) return {};
  const fct::MetalMaskDetector detector;
  // The review's DRR as registration renders it: with the case's default bone contrast.
  fct::DrrValueOptions drrValues;
  drrValues.boneContrast = fct::RegistrationCaseOptions::kDefaultBoneContrast;
  const auto drrVolume = std::make_shared<const fct::DrrVolume>(fct::DrrVolume::create(ct, drrValues).value());
  const fct::SiddonRayCaster drrRenderer(drrVolume);
  const auto cutFaces = fct::CutFaceRayMask::create(*drrVolume, 5.0);
  EXPECT_TRUE(cutFaces.ok()) << cutFaces.error();
  if (!cutFaces) return {};
  // The pose the review sees in a registration: the truth moved by about what the first stage leaves.
  const Eigen::Isometry3d T_review = fct::PoseOffset::apply(
      bone, T_truth, fct::PoseParameters{Eigen::Vector3d::Constant(0.3), Eigen::Vector3d::Constant(0.5)});
  std::vector<ViewMeasure> measures;
  for (std::size_t v = 0; v < views.size(); ++v) {
    ViewMeasure measure{views[v].name, 0.0, 0.0, 0.0, 1.0, 0};
    const Prepared metalFree = prepare(freeImages[v], cameras[v]);
    const auto freeMask = detector.detect(metalFree.lineIntegrals, metalFree.mask, spacing_mm);
    EXPECT_TRUE(freeMask.ok()) << freeMask.error();
    if (!freeMask) return measures;
    const double validCount = static_cast<double>(metalFree.mask.validCount());
    measure.falsePositive = static_cast<double>(freeMask.value().metalPixelCount) / validCount;
    const auto drr = drrRenderer.render(cameras[v], T_review);
    EXPECT_TRUE(drr.ok()) << drr.error();
    if (!drr) return measures;
    const fct::ValidMask covered = cutFaces.value().compute(cameras[v], T_review);
    const auto reviewed = fct::MetalMaskReview().review(metalFree.mask, freeMask.value().mask, metalFree.lineIntegrals,
                                                        drr.value(), covered, spacing_mm);
    EXPECT_TRUE(reviewed.ok()) << reviewed.error();
    if (!reviewed) return measures;
    measure.reviewedFalsePositive = static_cast<double>(reviewed.value().metalPixelCount) / validCount;
    const auto compared = metalFree.mask.excludedFractionWithin(reviewed.value().mask, covered);
    EXPECT_TRUE(compared.ok()) << compared.error();
    if (!compared) return measures;
    measure.comparedFalsePositive = compared.value();
    if (coverage) {
      const Prepared withTools = prepare(toolImages[v], cameras[v]);
      const auto toolMask = detector.detect(withTools.lineIntegrals, withTools.mask, spacing_mm);
      EXPECT_TRUE(toolMask.ok()) << toolMask.error();
      if (!toolMask) return measures;
      std::size_t covered = 0;
      for (std::size_t i = 0; i < toolImages[v].pixels.size(); ++i) {
        const double raise = std::log(std::max(freeImages[v].pixels[i], 1e-6f) /
                                      std::max(toolImages[v].pixels[i], 1e-6f));
        if (!withTools.mask.valid[i] || raise <= 0.5) continue;
        ++measure.toolPixels;
        if (!toolMask.value().mask.valid[i]) ++covered;
      }
      measure.coverage =
          static_cast<double>(covered) / static_cast<double>(std::max<std::size_t>(1, measure.toolPixels));
    }
    const std::string covers =
        coverage ? fmt::format("{:.1f} % of {} px", 100.0 * measure.coverage, measure.toolPixels) : "-";
    std::printf("| %s | %s | %dx%d px of %.1f mm | %.2f %% | %.2f %% | %.2f %% | %s |\n", label.c_str(),
                measure.view.c_str(), cols, rows, spacing_mm, 100.0 * measure.falsePositive,
                100.0 * measure.reviewedFalsePositive, 100.0 * measure.comparedFalsePositive, covers.c_str());
    measures.push_back(measure);
  }
  return measures;
}

/// Loads a CT of the shared data folder (the caller has checked it exists).
fct::Volume loadCt(const std::string& relative) {
  auto ct = fct::CtLoader::load(fct::test::dataDir() / relative);
  EXPECT_TRUE(ct.ok()) << ct.error();
  return ct ? std::move(ct).value() : fct::Volume{};
}

/// Every view loses less than 0.5 % of the pixels the CT covers to false positives after the review.
void expectFewFalsePositives(const std::vector<ViewMeasure>& measures) {
  EXPECT_EQ(measures.size(), 5u);
  for (const ViewMeasure& m : measures) EXPECT_LT(m.comparedFalsePositive, 0.005) << m.view;
}

/// Every view's tools are masked over at least `minCoverage` of their pixels.
void expectCoverage(const std::vector<ViewMeasure>& measures, double minCoverage) {
  EXPECT_EQ(measures.size(), 5u);
  for (const ViewMeasure& m : measures) {
    EXPECT_GT(m.toolPixels, 100u) << m.view;
    EXPECT_GE(m.coverage, minCoverage) << m.view;
  }
}

constexpr const char* kHead = "ct/head_phantom_philips_bone";
constexpr const char* kPelvis = "ct/pelvis_totalseg.nii.gz";

}  // namespace

TEST(MetalMaskFalsePositives, PhantomMetalFreeViewsLoseUnderHalfAPercent) {
  expectFewFalsePositives(measureViews(fct::PhantomBuilder::build({}).value(), "phantom", 192, 144, 1.6, false));
}

TEST(MetalMaskFalsePositives, HeadPhantomMetalFreeViewsLoseUnderHalfAPercent) {
  FCT_REQUIRE_DATA(kHead);
  expectFewFalsePositives(measureViews(loadCt(kHead), "head", 192, 144, 1.6, false));
}

TEST(MetalMaskFalsePositives, PelvisMetalFreeViewsLoseUnderHalfAPercent) {
  FCT_REQUIRE_DATA(kPelvis);
  expectFewFalsePositives(measureViews(loadCt(kPelvis), "pelvis", 192, 144, 1.6, false));
}

TEST(MetalMaskCoverage, PhantomKWiresAndScrewsAreMasked) {
  expectCoverage(measureViews(fct::PhantomBuilder::build({}).value(), "phantom", 192, 144, 1.6, true), 0.6);
}

TEST(MetalMaskCoverage, HeadPhantomKWiresAndScrewsAreMasked) {
  FCT_REQUIRE_DATA(kHead);
  expectCoverage(measureViews(loadCt(kHead), "head", 192, 144, 1.6, true), 0.8);
}

TEST(MetalMaskCoverage, PelvisKWiresAndScrewsAreMasked) {
  // At 1.6 mm pixels a 2 mm K-wire over the pelvis stands less than 1.0 above its surroundings in some views: the
  // screws and the wires' stronger parts are found.
  FCT_REQUIRE_DATA(kPelvis);
  expectCoverage(measureViews(loadCt(kPelvis), "pelvis", 192, 144, 1.6, true), 0.55);
}

TEST(MetalMaskStudy, DISABLED_TablePerViewOnBothCtsAtTwoPixelSizes) {
  FCT_REQUIRE_DATA(kHead);
  FCT_REQUIRE_DATA(kPelvis);
  std::printf("| CT | view | detector | metal-free view flagged | after the review | after the review, rays the CT "
              "covers | tool pixels masked |\n|---|---|---|---|---|---|---|\n");
  for (const char* name : {kHead, kPelvis}) {
    const fct::Volume ct = loadCt(name);
    const std::string label = name == kHead ? "head phantom" : "pelvis";
    expectFewFalsePositives(measureViews(ct, label, 192, 144, 1.6, true));
    expectFewFalsePositives(measureViews(ct, label, 384, 288, 0.8, true));
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
