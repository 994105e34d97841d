// LineChart: a chart has the requested size, a white background, black axes and its series' colours; series that
// share a colour differ in marker; bad specs fail.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string>
#include <utility>

#include "Evaluation/LineChart.h"

namespace {

bool hasColour(const fct::RgbImage& image, const std::array<std::uint8_t, 3>& rgb) {
  for (int row = 0; row < image.rows; ++row)
    for (int col = 0; col < image.cols; ++col)
      if (image.at(col, row) == rgb) return true;
  return false;
}

}  // namespace

TEST(LineChart, DrawsAxesAndEverySeriesInItsColour) {
  fct::ChartSpec spec;
  spec.title = "Cumulative failure";
  spec.xLabel = "initial sTRE (mm)";
  spec.yLabel = "failure (%)";
  spec.series.push_back({"ncc", {10, 20, 30}, {0, 10, 40}, true});
  spec.series.push_back({"vlnc", {10, 20, 30}, {0, NAN, 20}, false});
  spec.width_px = 640;
  spec.height_px = 400;
  const auto image = fct::LineChart::draw(spec);
  ASSERT_TRUE(image.ok()) << image.error();
  EXPECT_EQ(image.value().cols, 640);
  EXPECT_EQ(image.value().rows, 400);
  EXPECT_EQ(image.value().at(2, 2), (std::array<std::uint8_t, 3>{255, 255, 255}));
  EXPECT_TRUE(hasColour(image.value(), {0, 0, 0}));
  EXPECT_TRUE(hasColour(image.value(), fct::LineChart::seriesColour(0)));
  EXPECT_TRUE(hasColour(image.value(), fct::LineChart::seriesColour(1)));
}

TEST(LineChart, LegendTakesTheCornerThatHidesTheFewestSeriesPixels) {
  // The legend's frame is the only horizontal run of 30 (160, 160, 160) pixels in a chart (text edges have single
  // grey pixels); find which corner of the plot area its top edge is in.
  const auto legendCorner = [](const fct::ChartSpec& spec) {
    const auto image = fct::LineChart::draw(spec);
    EXPECT_TRUE(image.ok()) << image.error();
    const int midCol = (80 + spec.width_px - 20) / 2, midRow = (50 + spec.height_px - 60) / 2;
    for (int row = 0; row < image.value().rows; ++row) {
      int run = 0;
      for (int col = 0; col < image.value().cols; ++col) {
        run = image.value().at(col, row) == std::array<std::uint8_t, 3>{160, 160, 160} ? run + 1 : 0;
        if (run == 30) return std::string(row < midRow ? "top" : "bottom") + (col < midCol ? "-left" : "-right");
      }
    }
    return std::string("none");
  };
  fct::ChartSpec spec;
  spec.width_px = 640;
  spec.height_px = 400;
  spec.series.push_back({"flat", {0, 10}, {1, 1}, true});  // along the bottom: the top-right corner is free
  EXPECT_EQ(legendCorner(spec), "top-right");
  spec.series.front() = {"rising", {0, 10}, {0, 10}, true};  // bottom-left to top-right
  EXPECT_EQ(legendCorner(spec), "top-left");
  spec.series.front() = {"falling", {0, 10}, {10, 0}, true};  // top-left to bottom-right
  EXPECT_EQ(legendCorner(spec), "top-right");
  spec.series.push_back({"high", {0, 10}, {9.5, 9.5}, true});  // and a line along the top
  EXPECT_EQ(legendCorner(spec), "bottom-left");
}

TEST(LineChart, TheFirst28SeriesDifferInColourOrMarker) {
  std::set<std::pair<std::array<std::uint8_t, 3>, fct::ChartMarker>> looks;
  for (std::size_t n = 0; n < 28; ++n) looks.insert({fct::LineChart::seriesColour(n), fct::LineChart::seriesMarker(n)});
  EXPECT_EQ(looks.size(), 28u);
  EXPECT_EQ(fct::LineChart::seriesMarker(0), fct::ChartMarker::Disc);
  EXPECT_EQ(fct::LineChart::seriesColour(7), fct::LineChart::seriesColour(0));
  EXPECT_NE(fct::LineChart::seriesMarker(7), fct::ChartMarker::Disc);

  fct::ChartSpec spec;  // twelve series, as the capture study's chart has, all drawn
  for (int n = 0; n < 12; ++n) spec.series.push_back({fmt::format("s{}", n), {0.0, 1.0}, {0.1 * n, 0.1 * n + 1}, true});
  EXPECT_TRUE(fct::LineChart::draw(spec).ok());
}

TEST(LineChart, CategoryAxisAcceptsIndicesOfItsCategories) {
  fct::ChartSpec spec;
  spec.categories = {"ideal", "realistic", "bad"};
  spec.series.push_back({"pelvis", {0, 1, 2}, {0.2, 0.3, 0.9}, false});
  EXPECT_TRUE(fct::LineChart::draw(spec).ok());
  spec.series.front().x = {0, 1, 3};
  EXPECT_FALSE(fct::LineChart::draw(spec).ok());
}

TEST(LineChart, APointOnTheTopOfTheAxisShowsItsWholeMarkerOverTheFrame) {
  // A 100 % success rate on an axis that ends at 100: the discs (radius 4) reach above the frame's top row, 50.
  fct::ChartSpec spec;
  spec.categories = {"ideal", "realistic", "bad"};
  spec.series.push_back({"pelvis", {0, 1, 2}, {100, 100, 100}, false});
  spec.yMaxAtLeast = 100.0;
  const auto image = fct::LineChart::draw(spec);
  ASSERT_TRUE(image.ok()) << image.error();
  int aboveFrame = 0;
  for (int row = 44; row < 50; ++row) {
    for (int col = 80; col < spec.width_px - 20; ++col) {
      aboveFrame += image.value().at(col, row) == fct::LineChart::seriesColour(0) ? 1 : 0;
    }
  }
  EXPECT_GE(aboveFrame, 3 * 3);  // a few pixels of each of the three discs
}

TEST(LineChart, BadSpecsAreRejected) {
  fct::ChartSpec spec;
  EXPECT_FALSE(fct::LineChart::draw(spec).ok());  // no series
  spec.series.push_back({"a", {1, 2}, {1}, true});
  const auto mismatched = fct::LineChart::draw(spec);
  ASSERT_FALSE(mismatched.ok());
  EXPECT_NE(mismatched.error().find("2 x values but 1 y values"), std::string::npos) << mismatched.error();
  spec.series.front().y = {1, 2};
  spec.width_px = 100;
  EXPECT_FALSE(fct::LineChart::draw(spec).ok());
}
