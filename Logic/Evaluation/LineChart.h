#pragma once
// LineChart: a small 2D chart drawn with OpenCV into an RGB image (white background, framed plot area, x and y axes
// with ticks at "nice" steps and numeric or category tick labels, axis labels, a title and a legend in the corner of
// the plot area that hides the fewest series pixels), for the evaluation reports. Each series is a polyline with
// markers (or markers only); NaN points are skipped, and a point on an axis limit shows its whole marker. Series n has
// colour n of a 7-colour cycle and, from the 8th series on, a marker shape of its own for each further cycle, so that
// no two of the first 28 series look alike.

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "Base/Result.h"
#include "Image/RgbImage.h"

namespace fct {

/// One data series of a chart.
struct ChartSeries {
  std::string name;            ///< legend text
  std::vector<double> x;       ///< x values (category index 0, 1, ... for a category axis)
  std::vector<double> y;       ///< y values, same count as x; NaN = no point
  bool lines = true;           ///< join the points (false: markers only)
};

/// What a chart shows.
struct ChartSpec {
  std::string title;
  std::string xLabel;
  std::string yLabel;
  std::vector<std::string> categories;  ///< non-empty: the x axis is categorical, tick i at x = i labelled categories[i]
  std::vector<ChartSeries> series;
  double yMin = 0.0;                    ///< lower y limit (the upper one is chosen from the data)
  double yMaxAtLeast = 1.0;             ///< the y axis reaches at least this value
  int width_px = 900;
  int height_px = 560;
};

/// The marker shape of a series.
enum class ChartMarker { Disc, Square, Diamond, Triangle };

/// Draws charts.
class LineChart {
 public:
  /// Draws the chart. Fails on no series, a series whose x and y counts differ, a size below 320 x 240 pixels,
  /// non-finite limits, or a category axis with an x outside its categories.
  static Result<RgbImage> draw(const ChartSpec& spec);
  /// Draws the chart and writes it as an 8-bit RGB PNG (atomically); fails as draw() or on an unwritable path.
  static Status writePng(const ChartSpec& spec, const std::filesystem::path& path);
  /// The colour of series n (a fixed, colour-blind-friendly cycle of 7), RGB.
  static std::array<std::uint8_t, 3> seriesColour(std::size_t n);
  /// The marker of series n: a filled disc for the first 7, then one outline shape per further cycle of 7 colours.
  static ChartMarker seriesMarker(std::size_t n);
};

}  // namespace fct
