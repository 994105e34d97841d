#include <gtest/gtest.h>

#include "Similarity/DynamicRoiSelector.h"
#include "Similarity/GradientCorrelationSimilarity.h"
#include "Similarity/NccSimilarity.h"
#include "Similarity/VlncSimilarity.h"
#include "SyntheticImages.h"

namespace {

/// The phantom shifted right by `shift_px` columns (edge-replicated), as a DRR at a slightly wrong pose.
fct::FloatImage shifted(const fct::FloatImage& image, int shift_px) {
  fct::FloatImage out = image;
  for (int r = 0; r < image.rows; ++r) {
    for (int c = 0; c < image.cols; ++c) out.at(c, r) = image.at(std::max(0, c - shift_px), r);
  }
  return out;
}

struct Scores {
  double ncc, vlncRois, vlncAll, gc;
};

struct Tool {
  int row0, row1, col0, col1;  ///< rows and columns covered (half-open)
  float lineIntegral;          ///< added to the X-ray's line integral under the tool
};

struct Metrics {
  fct::NccSimilarity ncc;
  fct::VlncSimilarity vlncRois;
  fct::VlncSimilarity vlncAll;
  fct::GradientCorrelationSimilarity gc;

  Scores score(const fct::FloatImage& drr) const {
    return Scores{ncc.evaluate(drr).value(), vlncRois.evaluate(drr).value(), vlncAll.evaluate(drr).value(),
                  gc.evaluate(drr).value()};
  }
};

/// The phantom with `tool` added (the X-ray) and the metrics built on it: NCC and GC on all pixels, VLNC on the
/// 15 % dynamic ROIs and on all 7x7 windows.
Metrics metricsWithTool(const fct::FloatImage& anatomy, const Tool& tool) {
  fct::FloatImage xray = anatomy;
  for (int r = tool.row0; r < tool.row1; ++r) {
    for (int c = tool.col0; c < tool.col1; ++c) xray.at(c, r) += tool.lineIntegral;
  }
  const fct::ValidMask all = fct::ValidMask::allValid(xray.cols, xray.rows);
  const auto selector = fct::DynamicRoiSelector::create(xray, all).value();
  return Metrics{fct::NccSimilarity::create(xray, all.pixelList()).value(),
                 fct::VlncSimilarity::create(xray, selector.selectFraction(0.15).value()).value(),
                 fct::VlncSimilarity::create(xray, selector.selectAll()).value(),
                 fct::GradientCorrelationSimilarity::create(xray, all.pixelList()).value()};
}

void print(const char* label, const Scores& s) {
  std::printf("%-28s NCC %.3f  VLNC(ROIs) %.3f  VLNC(all windows) %.3f  GC %.3f\n", label, s.ncc, s.vlncRois, s.vlncAll,
              s.gc);
}

}  // namespace

// A broad, low-contrast occluder (a plate, +1 line integral over 45 % of the image) is a large-scale intensity change:
// it lowers whole-image NCC more than VLNC on dynamic ROIs, whose windows inside the plate see only an offset.
TEST(SimilarityOcclusion, BroadPlateLowersNccMoreThanVlncOnRois) {
  const fct::FloatImage anatomy = fct::test::phantomImage();
  const Metrics metrics = metricsWithTool(anatomy, Tool{30, 80, 0, 128, 1.0f});
  const Scores atTruth = metrics.score(anatomy);
  print("plate, true pose:", atTruth);
  EXPECT_LT(atTruth.ncc, atTruth.vlncRois);
  EXPECT_LT(atTruth.ncc, 0.95);
  const Scores off = metrics.score(shifted(anatomy, 2));
  print("plate, 2 px off:", off);
  EXPECT_GT(atTruth.ncc, off.ncc);
  EXPECT_GT(atTruth.vlncRois, off.vlncRois);
  EXPECT_GT(atTruth.vlncAll, off.vlncAll);
  EXPECT_GT(atTruth.gc, off.gc);
}

// A thin, dense tool (a K-wire: +1.5 over 3 rows) or a wide dense bar (+4): every metric still scores the true
// alignment above a 2 px shift, and VLNC separates the two more sharply than NCC. (VLNC's value itself drops more than
// NCC's here: the tool's own edges have the highest X-ray variance and so the largest VLNC weights.)
TEST(SimilarityOcclusion, DenseToolsKeepTheTruePoseBest) {
  const fct::FloatImage anatomy = fct::test::phantomImage();
  for (const Tool& tool : {Tool{44, 47, 0, 90, 1.5f}, Tool{40, 52, 0, 90, 4.0f}}) {
    const Metrics metrics = metricsWithTool(anatomy, tool);
    const Scores atTruth = metrics.score(anatomy);
    const Scores off = metrics.score(shifted(anatomy, 2));
    print(tool.lineIntegral < 2 ? "K-wire, true pose:" : "bar, true pose:", atTruth);
    print(tool.lineIntegral < 2 ? "K-wire, 2 px off:" : "bar, 2 px off:", off);
    EXPECT_GT(atTruth.ncc, off.ncc);
    EXPECT_GT(atTruth.vlncRois, off.vlncRois);
    EXPECT_GT(atTruth.vlncAll, off.vlncAll);
    EXPECT_GT(atTruth.gc, off.gc);
    EXPECT_GT(atTruth.vlncAll - off.vlncAll, atTruth.ncc - off.ncc);
  }
}
