#include "XrayPrep/DiscErosion.h"

#include <opencv2/imgproc.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <vector>

namespace fct {

// The element's rows are centred chords. Per band of output rows, each source row's minima over chords of every
// half-width w are made by widening those of w - 1 by a pixel on each side, and each output row takes the minimum of
// its chords' rows.
cv::Mat discErosion(const cv::Mat& image, int side, float outside) {
  if (image.type() != CV_32F || side < 1 || side % 2 == 0) {
    CV_Error(cv::Error::StsBadArg, "disc erosion needs a float image and an odd side");
  }
  const cv::Mat element = cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(side, side));
  const int radius = side / 2, rows = image.rows, cols = image.cols;
  std::vector<int> halfWidth(static_cast<std::size_t>(side), -1);  // per element row; -1: empty
  for (int r = 0; r < side; ++r) {
    for (int c = 0; c < side; ++c) {
      if (element.at<std::uint8_t>(r, c)) halfWidth[static_cast<std::size_t>(r)] = std::max(halfWidth[r], std::abs(c - radius));
    }
  }
  const int widest = std::max(0, *std::max_element(halfWidth.begin(), halfWidth.end()));
  const auto stride = static_cast<std::size_t>(cols);
  cv::Mat out(rows, cols, CV_32F, cv::Scalar(outside));
  // One band of rows per thread: a band recomputes the chords of the `radius` rows above and below it.
  const int bandRows = std::max(1, (rows + tbb::this_task_arena::max_concurrency() - 1) / tbb::this_task_arena::max_concurrency());
  tbb::parallel_for(tbb::blocked_range<int>(0, rows, bandRows), [&](const tbb::blocked_range<int>& band) {
    std::vector<float> padded(stride + 2 * static_cast<std::size_t>(widest), outside);
    std::vector<float> chords(stride * (static_cast<std::size_t>(widest) + 1));  // chords[w * cols + x]
    const int first = std::max(0, band.begin() - radius), last = std::min(rows, band.end() + radius);
    for (int sourceRow = first; sourceRow < last; ++sourceRow) {
      const float* source = image.ptr<float>(sourceRow);
      std::copy(source, source + cols, padded.begin() + widest);
      const float* centre = padded.data() + widest;
      std::copy(source, source + cols, chords.begin());
      for (int w = 1; w <= widest; ++w) {
        const float* previous = chords.data() + static_cast<std::size_t>(w - 1) * stride;
        float* current = chords.data() + static_cast<std::size_t>(w) * stride;
        for (int x = 0; x < cols; ++x) current[x] = std::min(previous[x], std::min(centre[x - w], centre[x + w]));
      }
      for (int r = 0; r < side; ++r) {
        const int y = sourceRow - (r - radius);
        const int w = halfWidth[static_cast<std::size_t>(r)];
        if (y < band.begin() || y >= band.end() || w < 0) continue;
        const float* chord = chords.data() + static_cast<std::size_t>(w) * stride;
        float* target = out.ptr<float>(y);
        for (int x = 0; x < cols; ++x) target[x] = std::min(target[x], chord[x]);
      }
    }
  }, tbb::simple_partitioner());
  return out;
}

}  // namespace fct
