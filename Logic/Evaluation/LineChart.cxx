#include "Evaluation/LineChart.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "IO/Xray/ImageFileWriter.h"

namespace fct {

namespace {

constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
constexpr double kTextScale = 0.5;
constexpr double kTitleScale = 0.65;
const cv::Scalar kBlack(0, 0, 0);
const cv::Scalar kGrid(225, 225, 225);

/// A "nice" tick step (1, 2 or 5 times a power of ten) giving about `ticks` intervals over `range`.
double niceStep(double range, int ticks) {
  const double raw = range / ticks;
  const double power = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * power >= raw) return m * power;
  }
  return 10.0 * power;
}

/// A tick label without trailing zeros ("10", "2.5", "0.25").
std::string tickText(double value, double step) {
  const int decimals = std::clamp(static_cast<int>(std::ceil(-std::log10(step) + 1e-9)), 0, 4);
  return fmt::format("{:.{}f}", std::abs(value) < 1e-12 ? 0.0 : value, decimals);
}

cv::Size textSize(const std::string& text, double scale) {
  int baseline = 0;
  return cv::getTextSize(text, kFont, scale, 1, &baseline);
}

/// Draws `text` centred horizontally at x, with its baseline at y.
void centredText(cv::Mat& image, const std::string& text, int x, int y, double scale) {
  cv::putText(image, text, cv::Point(x - textSize(text, scale).width / 2, y), kFont, scale, kBlack, 1, cv::LINE_AA);
}

/// Draws `text` rotated by 90 degrees (reading upwards), centred vertically at y, its left edge at x.
void verticalText(cv::Mat& image, const std::string& text, int x, int y) {
  const cv::Size size = textSize(text, kTextScale);
  cv::Mat horizontal(size.height + 8, size.width + 4, CV_8UC3, cv::Scalar(255, 255, 255));
  cv::putText(horizontal, text, cv::Point(2, size.height + 2), kFont, kTextScale, kBlack, 1, cv::LINE_AA);
  cv::Mat rotated;
  cv::rotate(horizontal, rotated, cv::ROTATE_90_COUNTERCLOCKWISE);
  const int top = std::clamp(y - rotated.rows / 2, 0, image.rows - rotated.rows);
  const int left = std::clamp(x, 0, image.cols - rotated.cols);
  rotated.copyTo(image(cv::Rect(left, top, rotated.cols, rotated.rows)));
}

/// Series colours, RGB: the Okabe-Ito palette (without yellow, too faint on white), then black.
constexpr std::array<std::array<std::uint8_t, 3>, 7> kSeriesColours{
    {{0, 114, 178}, {213, 94, 0}, {0, 158, 115}, {204, 121, 167}, {86, 180, 233}, {230, 159, 0}, {0, 0, 0}}};

cv::Scalar bgr(std::size_t n) {
  const auto c = LineChart::seriesColour(n);
  return cv::Scalar(c[2], c[1], c[0]);
}

/// Draws series n's marker centred at `at` (a filled disc of radius 4, or an outline shape about 10 px across).
void drawSeriesMarker(cv::Mat& image, const cv::Point& at, std::size_t n) {
  switch (LineChart::seriesMarker(n)) {
    case ChartMarker::Disc: cv::circle(image, at, 4, bgr(n), cv::FILLED, cv::LINE_AA); return;
    case ChartMarker::Square: cv::drawMarker(image, at, bgr(n), cv::MARKER_SQUARE, 10, 2, cv::LINE_AA); return;
    case ChartMarker::Diamond: cv::drawMarker(image, at, bgr(n), cv::MARKER_DIAMOND, 12, 2, cv::LINE_AA); return;
    case ChartMarker::Triangle: cv::drawMarker(image, at, bgr(n), cv::MARKER_TRIANGLE_UP, 12, 2, cv::LINE_AA); return;
  }
}

Result<RgbImage> drawUnguarded(const ChartSpec& spec);

}  // namespace

std::array<std::uint8_t, 3> LineChart::seriesColour(std::size_t n) { return kSeriesColours[n % kSeriesColours.size()]; }

ChartMarker LineChart::seriesMarker(std::size_t n) {
  static constexpr std::array<ChartMarker, 4> kMarkers{ChartMarker::Disc, ChartMarker::Square, ChartMarker::Diamond,
                                                       ChartMarker::Triangle};
  return kMarkers[(n / kSeriesColours.size()) % kMarkers.size()];
}

Result<RgbImage> LineChart::draw(const ChartSpec& spec) {
  try {
    return drawUnguarded(spec);
  } catch (const cv::Exception& e) {
    return fail(fmt::format("chart '{}' could not be drawn: {}", spec.title, e.what()));
  }
}

namespace {

Result<RgbImage> drawUnguarded(const ChartSpec& spec) {
  if (spec.series.empty()) return fail(fmt::format("chart '{}' has no data series", spec.title));
  if (spec.width_px < 320 || spec.height_px < 240) {
    return fail(fmt::format("chart '{}' is {}x{} pixels; use at least 320x240", spec.title, spec.width_px,
                            spec.height_px));
  }
  if (!std::isfinite(spec.yMin) || !std::isfinite(spec.yMaxAtLeast)) {
    return fail(fmt::format("chart '{}': the y limits must be finite", spec.title));
  }
  const bool categorical = !spec.categories.empty();
  double xLo = std::numeric_limits<double>::infinity(), xHi = -xLo;
  double yHi = std::max(spec.yMaxAtLeast, spec.yMin);
  for (const ChartSeries& s : spec.series) {
    if (s.x.size() != s.y.size()) {
      return fail(fmt::format("chart '{}': series '{}' has {} x values but {} y values", spec.title, s.name,
                              s.x.size(), s.y.size()));
    }
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if (!std::isfinite(s.x[i])) return fail(fmt::format("chart '{}': series '{}' has a non-finite x", spec.title, s.name));
      if (categorical && (s.x[i] < 0 || s.x[i] > static_cast<double>(spec.categories.size()) - 1)) {
        return fail(fmt::format("chart '{}': series '{}' has x = {} outside its {} categories", spec.title, s.name,
                                s.x[i], spec.categories.size()));
      }
      xLo = std::min(xLo, s.x[i]);
      xHi = std::max(xHi, s.x[i]);
      if (std::isfinite(s.y[i])) yHi = std::max(yHi, s.y[i]);
    }
  }
  if (categorical) {
    xLo = -0.5;
    xHi = static_cast<double>(spec.categories.size()) - 0.5;
  } else if (!(xHi > xLo)) {
    xLo = std::isfinite(xLo) ? xLo - 1.0 : 0.0;
    xHi = xLo + 2.0;
  }
  const double yStep = niceStep(yHi - spec.yMin, 5);
  yHi = spec.yMin + std::ceil((yHi - spec.yMin) / yStep - 1e-9) * yStep;
  if (!(yHi > spec.yMin)) yHi = spec.yMin + yStep;

  cv::Mat image(spec.height_px, spec.width_px, CV_8UC3, cv::Scalar(255, 255, 255));
  const int left = 80, right = spec.width_px - 20, top = 50, bottom = spec.height_px - (categorical ? 80 : 60);
  const auto px = [&](double x) { return static_cast<int>(std::lround(left + (x - xLo) / (xHi - xLo) * (right - left))); };
  const auto py = [&](double y) { return static_cast<int>(std::lround(bottom - (y - spec.yMin) / (yHi - spec.yMin) * (bottom - top))); };

  // Grid, ticks and tick labels.
  for (double y = spec.yMin; y <= yHi + 1e-9 * yStep; y += yStep) {
    const int row = py(y);
    cv::line(image, cv::Point(left, row), cv::Point(right, row), kGrid, 1);
    cv::line(image, cv::Point(left - 5, row), cv::Point(left, row), kBlack, 1);
    const std::string label = tickText(y, yStep);
    cv::putText(image, label, cv::Point(left - 8 - textSize(label, kTextScale).width, row + 5), kFont, kTextScale,
                kBlack, 1, cv::LINE_AA);
  }
  if (categorical) {
    // Names wider than their slot alternate between two rows so neighbours do not overlap.
    const double slot_px = static_cast<double>(right - left) / static_cast<double>(spec.categories.size());
    bool stagger = false;
    for (const std::string& name : spec.categories) stagger = stagger || textSize(name, kTextScale).width > slot_px - 8;
    for (std::size_t i = 0; i < spec.categories.size(); ++i) {
      const int col = px(static_cast<double>(i));
      cv::line(image, cv::Point(col, bottom), cv::Point(col, bottom + 5), kBlack, 1);
      centredText(image, spec.categories[i], col, bottom + 20 + (stagger ? static_cast<int>(i % 2) * 18 : 0), kTextScale);
    }
  } else {
    const double xStep = niceStep(xHi - xLo, 6);
    for (double x = std::ceil(xLo / xStep - 1e-9) * xStep; x <= xHi + 1e-9 * xStep; x += xStep) {
      const int col = px(x);
      cv::line(image, cv::Point(col, top), cv::Point(col, bottom), kGrid, 1);
      cv::line(image, cv::Point(col, bottom), cv::Point(col, bottom + 5), kBlack, 1);
      centredText(image, tickText(x, xStep), col, bottom + 20, kTextScale);
    }
  }
  cv::rectangle(image, cv::Point(left, top), cv::Point(right, bottom), kBlack, 1);
  centredText(image, spec.title, spec.width_px / 2, 30, kTitleScale);
  centredText(image, spec.xLabel, (left + right) / 2, spec.height_px - 12, kTextScale);
  verticalText(image, spec.yLabel, 8, (top + bottom) / 2);

  // Series, their lines clipped to the plot area; `drawn` marks their pixels (plot-area coordinates) for the
  // legend's placement.
  const cv::Rect plotArea(left, top, right - left + 1, bottom - top + 1);
  cv::Mat plot = image(plotArea);
  cv::Mat drawn(plot.size(), CV_8U, cv::Scalar(0));
  const cv::Point origin = plotArea.tl();
  for (std::size_t n = 0; n < spec.series.size(); ++n) {
    const ChartSeries& s = spec.series[n];
    std::vector<std::pair<double, double>> points;
    // On a category axis the series sit side by side around each category's tick.
    const double shift = categorical ? 0.08 * (static_cast<double>(n) - 0.5 * (spec.series.size() - 1.0)) : 0.0;
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if (std::isfinite(s.y[i])) points.emplace_back(s.x[i] + shift, s.y[i]);
    }
    if (s.lines) std::sort(points.begin(), points.end());
    for (std::size_t i = 0; i < points.size(); ++i) {
      const cv::Point p(px(points[i].first), py(points[i].second));
      if (s.lines && i > 0) {
        const cv::Point previous(px(points[i - 1].first), py(points[i - 1].second));
        cv::line(plot, previous - origin, p - origin, bgr(n), 2, cv::LINE_AA);
        cv::line(drawn, previous - origin, p - origin, cv::Scalar(255), 2);
      }
      // A point on the axes' range shows its whole marker, over the frame where it sits on an axis limit (a 100 %
      // success rate); a point beyond the range is clipped to the plot area with its line.
      const bool onRange = points[i].second >= spec.yMin && points[i].second <= yHi && points[i].first >= xLo &&
                           points[i].first <= xHi;
      if (onRange) {
        drawSeriesMarker(image, p, n);
      } else {
        drawSeriesMarker(plot, p - origin, n);
      }
      cv::circle(drawn, p - origin, 6, cv::Scalar(255), cv::FILLED);
    }
  }

  // Legend in the corner of the plot area that hides the fewest series pixels (top-right on a tie).
  int legendWidth = 0;
  for (const ChartSeries& s : spec.series) legendWidth = std::max(legendWidth, textSize(s.name, kTextScale).width);
  const int boxWidth = legendWidth + 42, boxHeight = 20 * static_cast<int>(spec.series.size()) + 8;
  const int nearLeft = left + 8, nearRight = right - legendWidth - 50;
  const int nearTop = top + 8, nearBottom = bottom - 8 - boxHeight;
  cv::Rect box;
  int hidden = std::numeric_limits<int>::max();
  for (const cv::Point corner : {cv::Point(nearRight, nearTop), cv::Point(nearLeft, nearTop),
                                 cv::Point(nearRight, nearBottom), cv::Point(nearLeft, nearBottom)}) {
    const cv::Rect candidate(corner, cv::Size(boxWidth, boxHeight));
    const cv::Rect overPlot = (candidate - origin) & cv::Rect(cv::Point(), drawn.size());
    const int pixels = overPlot.area() > 0 ? cv::countNonZero(drawn(overPlot)) : 0;
    if (pixels < hidden) {
      hidden = pixels;
      box = candidate;
    }
  }
  const int boxLeft = box.x, boxTop = box.y;
  cv::rectangle(image, box, cv::Scalar(255, 255, 255), cv::FILLED);
  cv::rectangle(image, box, cv::Scalar(160, 160, 160), 1);
  for (std::size_t n = 0; n < spec.series.size(); ++n) {
    const int row = boxTop + 16 + 20 * static_cast<int>(n);
    if (spec.series[n].lines) {
      cv::line(image, cv::Point(boxLeft + 6, row - 4), cv::Point(boxLeft + 28, row - 4), bgr(n), 2, cv::LINE_AA);
    }
    drawSeriesMarker(image, cv::Point(boxLeft + 17, row - 4), n);
    cv::putText(image, spec.series[n].name, cv::Point(boxLeft + 34, row), kFont, kTextScale, kBlack, 1, cv::LINE_AA);
  }

  RgbImage rgb;
  rgb.cols = image.cols;
  rgb.rows = image.rows;
  rgb.pixels.resize(static_cast<std::size_t>(image.cols) * image.rows * 3);
  cv::Mat wrapped(image.rows, image.cols, CV_8UC3, rgb.pixels.data());
  cv::cvtColor(image, wrapped, cv::COLOR_BGR2RGB);
  return rgb;
}

}  // namespace

Status LineChart::writePng(const ChartSpec& spec, const std::filesystem::path& path) {
  auto image = draw(spec);
  if (!image) return fail(image.error());
  return ImageFileWriter::writePngRgb(image.value(), path);
}

}  // namespace fct
